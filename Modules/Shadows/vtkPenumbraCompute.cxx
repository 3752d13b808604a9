#include "vtkPenumbraCompute.h"

#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtk_glew.h"

#include <algorithm>
#include <sstream>

namespace penumbra_compute
{
//------------------------------------------------------------------------------
std::string GLErrorText(unsigned int error)
{
  std::ostringstream os;
  os << "OpenGL error 0x" << std::hex << error;
  return os.str();
}

//------------------------------------------------------------------------------
ProgramScope::ProgramScope(vtkOpenGLRenderWindow* window, unsigned int program)
{
  window->GetShaderCache()->ReleaseCurrentShader();
  glUseProgram(program);
}

//------------------------------------------------------------------------------
ProgramScope::~ProgramScope()
{
  glUseProgram(0);
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
}

//------------------------------------------------------------------------------
bool Device::Prepare(vtkOpenGLRenderWindow* window, int blocks, const char* user, std::string& why)
{
  if (!window)
  {
    why = "no OpenGL render window (the compute path needs the renderer's context)";
    return false;
  }
  if (window != this->Window)
  {
    // Objects of another context die with it; start afresh in this one.
    this->Forget();
    this->Window = window;
    ++this->Generations;
  }
  window->MakeCurrent();
  if (!window->IsCurrent())
  {
    why = "the render window's OpenGL context cannot be made current";
    return false;
  }
  if (!this->Checked)
  {
    this->Checked = true;
    GLint major = 0, minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    const bool compute = major * 10 + minor >= 43 && glDispatchCompute && glGetBufferSubData;
    GLint maxBlocks = 0;
    GLint64 blockBytes = 0;
    if (compute)
    {
      glGetIntegerv(GL_MAX_COMPUTE_SHADER_STORAGE_BLOCKS, &maxBlocks);
      glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &blockBytes);
    }
    else
    {
      this->Unsupported = "OpenGL " + std::to_string(major) + "." + std::to_string(minor) +
        " has no compute shaders and shader storage buffers (4.3 needed)";
    }
    this->MaxBlocks = maxBlocks;
    this->MaxBlockBytes = blockBytes;
    while (glGetError() != GL_NO_ERROR)
    {
    }
  }
  if (!this->Unsupported.empty())
  {
    why = this->Unsupported;
    return false;
  }
  if (this->MaxBlocks < blocks)
  {
    why = "the context allows " + std::to_string(this->MaxBlocks) +
      " storage blocks per compute shader, the " + user + " shader needs " + std::to_string(blocks);
    return false;
  }
  if (this->Buffers.size() < static_cast<std::size_t>(blocks))
  {
    this->Buffers.resize(static_cast<std::size_t>(blocks), 0u);
    this->Capacity.resize(static_cast<std::size_t>(blocks), 0);
  }
  return true;
}

//------------------------------------------------------------------------------
bool Device::Compile(const std::string& source, unsigned int& program, std::string& why)
{
  const char* text = source.c_str();
  const GLuint shader = glCreateShader(GL_COMPUTE_SHADER);
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  auto log = [](GLuint object, bool isShader)
  {
    GLint length = 0;
    isShader ? glGetShaderiv(object, GL_INFO_LOG_LENGTH, &length)
             : glGetProgramiv(object, GL_INFO_LOG_LENGTH, &length);
    std::string message(static_cast<size_t>(std::max(length, 1)), '\0');
    isShader ? glGetShaderInfoLog(object, length, nullptr, &message[0])
             : glGetProgramInfoLog(object, length, nullptr, &message[0]);
    return message;
  };
  if (!ok)
  {
    why = "the compute shader does not compile: " + log(shader, true);
    glDeleteShader(shader);
    return false;
  }
  const GLuint id = glCreateProgram();
  glAttachShader(id, shader);
  glLinkProgram(id);
  glDeleteShader(shader);
  glGetProgramiv(id, GL_LINK_STATUS, &ok);
  if (!ok)
  {
    why = "the compute shader does not link: " + log(id, false);
    glDeleteProgram(id);
    return false;
  }
  this->Programs.push_back(id);
  program = id;
  return true;
}

//------------------------------------------------------------------------------
bool Device::Upload(int binding, const void* data, std::size_t bytes, std::string& why)
{
  const std::size_t b = static_cast<std::size_t>(binding);
  if (b >= this->Buffers.size())
  {
    why = "storage binding " + std::to_string(binding) + " was not prepared";
    return false;
  }
  if (this->MaxBlockBytes > 0 && static_cast<std::int64_t>(bytes) > this->MaxBlockBytes)
  {
    why = "a storage buffer of " + std::to_string(bytes) +
      " bytes exceeds the context's limit of " + std::to_string(this->MaxBlockBytes);
    return false;
  }
  if (!this->Buffers[b])
  {
    glGenBuffers(1, &this->Buffers[b]);
  }
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, this->Buffers[b]);
  // Never empty: a zero-sized storage binding is not portable.
  const std::size_t size = std::max<std::size_t>(bytes, 16);
  if (size > this->Capacity[b])
  {
    glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(size), nullptr, GL_DYNAMIC_DRAW);
    this->Capacity[b] = size;
  }
  if (data && bytes)
  {
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(bytes), data);
    this->UploadedBytes += bytes;
  }
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, static_cast<GLuint>(binding), this->Buffers[b]);
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR)
  {
    why = "uploading a storage buffer failed: " + GLErrorText(error);
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void Device::Bind(int binding) const
{
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, static_cast<GLuint>(binding), this->Buffer(binding));
}

//------------------------------------------------------------------------------
bool Device::Download(int binding, void* data, std::size_t bytes, std::string& why) const
{
  if (bytes == 0)
  {
    return true;
  }
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, this->Buffer(binding));
  glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(bytes), data);
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR)
  {
    why = "reading a storage buffer back failed: " + GLErrorText(error);
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
unsigned int Device::Buffer(int binding) const
{
  const std::size_t b = static_cast<std::size_t>(binding);
  return b < this->Buffers.size() ? this->Buffers[b] : 0u;
}

//------------------------------------------------------------------------------
void Device::Release(vtkWindow* window)
{
  auto* gl = vtkOpenGLRenderWindow::SafeDownCast(window);
  if (!gl || gl != this->Window)
  {
    return;
  }
  gl->MakeCurrent();
  if (gl->IsCurrent())
  {
    for (unsigned int program : this->Programs)
    {
      glDeleteProgram(program);
    }
    for (unsigned int& buffer : this->Buffers)
    {
      if (buffer)
      {
        glDeleteBuffers(1, &buffer);
      }
    }
  }
  this->Forget();
}

//------------------------------------------------------------------------------
void Device::Forget()
{
  this->Programs.clear();
  std::fill(this->Buffers.begin(), this->Buffers.end(), 0u);
  std::fill(this->Capacity.begin(), this->Capacity.end(), std::size_t(0));
  this->Window = nullptr;
  this->Checked = false;
  this->Unsupported.clear();
  this->MaxBlocks = 0;
  this->MaxBlockBytes = 0;
}
}
