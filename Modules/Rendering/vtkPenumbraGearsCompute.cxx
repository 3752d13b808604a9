#include "vtkPenumbraGearsCompute.h"

#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtk_glew.h"

#include "vtkPenumbraGearsMaskCS.h"

#include <algorithm>
#include <sstream>

namespace penumbra_gears
{
namespace
{
constexpr unsigned int LocalSize = 8;     // local_size_x of the shader
constexpr unsigned int MaxGroups = 65535; // GL 4.3's guaranteed work-group count per axis

// Scoped: our program bound, VTK's shader cache told that its program is no longer bound,
// storage bindings and the program released on exit.
class ProgramScope
{
public:
  ProgramScope(vtkOpenGLRenderWindow* window, unsigned int program)
  {
    window->GetShaderCache()->ReleaseCurrentShader();
    glUseProgram(program);
  }
  ~ProgramScope()
  {
    glUseProgram(0);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
  }
  ProgramScope(const ProgramScope&) = delete;
  ProgramScope& operator=(const ProgramScope&) = delete;
};

std::string GLErrorText(GLenum error)
{
  std::ostringstream os;
  os << "OpenGL error 0x" << std::hex << error;
  return os.str();
}
}

//------------------------------------------------------------------------------
MaskCompute::~MaskCompute() = default;

//------------------------------------------------------------------------------
bool MaskCompute::Prepare(
  vtkOpenGLRenderWindow* window, int k, int rows, bool keepMasks, std::string& why)
{
  if (!window)
  {
    why = "no OpenGL render window (the compute path needs the renderer's context)";
    return false;
  }
  if (k < 1 || k > 32 || rows < 1 || rows > 32)
  {
    why = "the compute path holds a mask row in 32 bits; " + std::to_string(k) +
      " light samples per row need the CPU path";
    return false;
  }
  if (window != this->Window)
  {
    // Objects of another context die with it; start afresh in this one.
    this->Forget();
    this->Window = window;
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
    GLint blocks = 0;
    GLint64 blockBytes = 0;
    if (major * 10 + minor >= 43 && glDispatchCompute && glGetBufferSubData)
    {
      glGetIntegerv(GL_MAX_COMPUTE_SHADER_STORAGE_BLOCKS, &blocks);
      glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &blockBytes);
    }
    this->MaxBlockBytes = blockBytes;
    if (major * 10 + minor < 43 || !glDispatchCompute || !glGetBufferSubData)
    {
      this->Unsupported = "OpenGL " + std::to_string(major) + "." + std::to_string(minor) +
        " has no compute shaders and shader storage buffers (4.3 needed)";
    }
    else if (blocks < BufferCount)
    {
      this->Unsupported = "the context allows " + std::to_string(blocks) +
        " storage blocks per compute shader, the GEARS shader needs " + std::to_string(BufferCount);
    }
    while (glGetError() != GL_NO_ERROR)
    {
    }
  }
  if (!this->Unsupported.empty())
  {
    why = this->Unsupported;
    return false;
  }
  const int key = (k << 16) | (rows << 1) | (keepMasks ? 1 : 0);
  auto found = this->Programs.find(key);
  if (found == this->Programs.end())
  {
    Program program;
    if (!this->Compile(k, rows, keepMasks, program, why))
    {
      return false;
    }
    found = this->Programs.emplace(key, program).first;
  }
  this->Current = &found->second;
  return true;
}

//------------------------------------------------------------------------------
bool MaskCompute::Compile(int k, int rows, bool keepMasks, Program& program, std::string& why)
{
  std::ostringstream header;
  header << "#version 430\n#define GEARS_K " << k << "\n#define GEARS_ROWS " << rows
         << "\n#define GEARS_KEEP_MASKS " << (keepMasks ? 1 : 0) << "\n#define GEARS_OWNER_STRIDE "
         << sizeof(vtkIdType) / 4 << "\n#define GEARS_LOCAL_SIZE " << LocalSize << "\n";
  const std::string source = header.str() + vtkPenumbraGearsMaskCS;
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
    std::string text(static_cast<size_t>(std::max(length, 1)), '\0');
    isShader ? glGetShaderInfoLog(object, length, nullptr, &text[0])
             : glGetProgramInfoLog(object, length, nullptr, &text[0]);
    return text;
  };
  if (!ok)
  {
    why = "the GEARS compute shader does not compile: " + log(shader, true);
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
    why = "the GEARS compute shader does not link: " + log(id, false);
    glDeleteProgram(id);
    return false;
  }
  program.Id = id;
  program.Rows = rows;
  const std::pair<int*, const char*> uniforms[] = { { &program.Centre, "uCentre" },
    { &program.AxisU, "uAxisU" }, { &program.AxisV, "uAxisV" }, { &program.AxisN, "uAxisN" },
    { &program.Shift, "uShift" }, { &program.Su0, "uSu0" }, { &program.DSu, "uDSu" },
    { &program.Sv0, "uSv0" }, { &program.DSv, "uDSv" }, { &program.Epsilon, "uEpsilon" },
    { &program.TieFactor, "uTieFactor" }, { &program.Diagonal, "uDiagonal" },
    { &program.FarSlack, "uFarSlack" }, { &program.Flip, "uFlip" },
    { &program.RelativeTolerance, "uRelativeTolerance" }, { &program.WorkOffset, "uWorkOffset" },
    { &program.WorkCount, "uWorkCount" }, { &program.GlobalCount, "uGlobalCount" },
    { &program.HasCasters, "uHasCasters" }, { &program.LoopProbe, "uLoopProbe" } };
  for (const auto& u : uniforms)
  {
    *u.first = glGetUniformLocation(id, u.second);
  }
  return true;
}

//------------------------------------------------------------------------------
bool MaskCompute::Upload(int buffer, const void* data, std::size_t bytes, std::string& why)
{
  if (this->MaxBlockBytes > 0 && static_cast<std::int64_t>(bytes) > this->MaxBlockBytes)
  {
    why = "a storage buffer of " + std::to_string(bytes) +
      " bytes exceeds the context's limit of " + std::to_string(this->MaxBlockBytes);
    return false;
  }
  if (!this->Buffers[buffer])
  {
    glGenBuffers(1, &this->Buffers[buffer]);
  }
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, this->Buffers[buffer]);
  // Never empty: a zero-sized storage binding is not portable.
  const std::size_t size = std::max<std::size_t>(bytes, 16);
  if (size > this->Capacity[buffer])
  {
    glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(size), nullptr, GL_DYNAMIC_DRAW);
    this->Capacity[buffer] = size;
  }
  if (data && bytes)
  {
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(bytes), data);
    this->UploadedBytes += bytes;
  }
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, static_cast<GLuint>(buffer), this->Buffers[buffer]);
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR)
  {
    why = "uploading a GEARS storage buffer failed: " + GLErrorText(error);
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
bool MaskCompute::SetCasters(
  const std::vector<double>& data, std::uint64_t version, std::string& why)
{
  if (version == this->CasterVersion && this->Buffers[Casters])
  {
    return true;
  }
  if (!this->Upload(Casters, data.data(), data.size() * sizeof(double), why))
  {
    return false;
  }
  this->CasterVersion = version;
  this->CasterCount = data.size() / CasterStride;
  return true;
}

//------------------------------------------------------------------------------
bool MaskCompute::SetSamples(const float* positions, const float* normals, const vtkIdType* owners,
  vtkIdType count, std::string& why)
{
  const std::size_t n = static_cast<std::size_t>(std::max<vtkIdType>(count, 0));
  return this->Upload(Positions, positions, 3 * n * sizeof(float), why) &&
    this->Upload(Normals, normals, 3 * n * sizeof(float), why) &&
    this->Upload(Owners, owners, n * sizeof(vtkIdType), why);
}

//------------------------------------------------------------------------------
bool MaskCompute::Run(const ComputeLight& light, const ComputeConstants& constants,
  const ComputeSide& side, std::vector<std::uint32_t>& results, std::vector<std::uint32_t>* masks,
  std::string& why)
{
  if (!this->Current || !this->Window)
  {
    why = "the compute path was not prepared";
    return false;
  }
  const Program& program = *this->Current;
  const std::size_t count = light.K * static_cast<std::size_t>(light.Rows);
  const std::size_t work = side.WorkCount;
  results.assign(3 * work, 0u);
  if (masks)
  {
    masks->assign(work * static_cast<std::size_t>(program.Rows), 0u);
  }
  if (work == 0)
  {
    return true;
  }
  // The casters stay bound from SetCasters(); rebind them all the same (another technique
  // may have used the binding points since).
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, Casters, this->Buffers[Casters]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, Positions, this->Buffers[Positions]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, Normals, this->Buffers[Normals]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, Owners, this->Buffers[Owners]);
  if (!this->Upload(ZNear, side.ZNear, this->CasterCount * sizeof(double), why) ||
    !this->Upload(CellStart, side.CellStart, (side.Cells + 1) * sizeof(std::uint32_t), why) ||
    !this->Upload(CellList, side.CellList, side.ListSize * sizeof(std::uint32_t), why) ||
    !this->Upload(GlobalList, side.GlobalList, side.GlobalSize * sizeof(std::uint32_t), why) ||
    !this->Upload(Work, side.Work, 2 * work * sizeof(std::uint32_t), why) ||
    !this->Upload(LightPoints, light.Points, 3 * count * sizeof(double), why) ||
    !this->Upload(Results, nullptr, 3 * work * sizeof(std::uint32_t), why) ||
    (masks && !this->Upload(Masks, nullptr, masks->size() * sizeof(std::uint32_t), why)))
  {
    return false;
  }
  {
    ProgramScope scope(this->Window, program.Id);
    glUniform3dv(program.Centre, 1, light.Centre);
    glUniform3dv(program.AxisU, 1, light.U);
    glUniform3dv(program.AxisV, 1, light.V);
    glUniform3dv(program.AxisN, 1, light.N);
    glUniform3dv(program.Shift, 1, constants.Shift);
    glUniform1d(program.Su0, light.Su0);
    glUniform1d(program.DSu, light.DSu);
    glUniform1d(program.Sv0, light.Sv0);
    glUniform1d(program.DSv, light.DSv);
    glUniform1d(program.Epsilon, constants.Epsilon);
    glUniform1d(program.TieFactor, constants.TieFactor);
    glUniform1d(program.Diagonal, constants.Diagonal);
    glUniform1d(program.FarSlack, side.FarSlack);
    glUniform1d(program.Flip, side.Flip);
    glUniform1d(program.RelativeTolerance, constants.RelativeTolerance);
    glUniform1ui(program.WorkCount, static_cast<GLuint>(work));
    glUniform1ui(program.GlobalCount, static_cast<GLuint>(side.GlobalSize));
    glUniform1i(program.HasCasters, this->CasterCount > 0 ? 1 : 0);
    glUniform1ui(program.LoopProbe, 2u);
    const std::size_t perDispatch = static_cast<std::size_t>(MaxGroups) * LocalSize;
    for (std::size_t offset = 0; offset < work; offset += perDispatch)
    {
      const std::size_t items = std::min(perDispatch, work - offset);
      glUniform1ui(program.WorkOffset, static_cast<GLuint>(offset));
      glDispatchCompute(static_cast<GLuint>((items + LocalSize - 1) / LocalSize), 1, 1);
    }
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, this->Buffers[Results]);
    glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0,
      static_cast<GLsizeiptr>(results.size() * sizeof(std::uint32_t)), results.data());
    if (masks)
    {
      glBindBuffer(GL_SHADER_STORAGE_BUFFER, this->Buffers[Masks]);
      glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0,
        static_cast<GLsizeiptr>(masks->size() * sizeof(std::uint32_t)), masks->data());
    }
  }
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR)
  {
    why = "the GEARS compute dispatch failed: " + GLErrorText(error);
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void MaskCompute::Release(vtkWindow* window)
{
  auto* gl = vtkOpenGLRenderWindow::SafeDownCast(window);
  if (!gl || gl != this->Window)
  {
    return;
  }
  gl->MakeCurrent();
  if (gl->IsCurrent())
  {
    for (auto& entry : this->Programs)
    {
      glDeleteProgram(entry.second.Id);
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
void MaskCompute::Forget()
{
  this->Programs.clear();
  this->Current = nullptr;
  std::fill(this->Buffers, this->Buffers + BufferCount, 0u);
  std::fill(this->Capacity, this->Capacity + BufferCount, std::size_t(0));
  this->CasterVersion = 0;
  this->Window = nullptr;
  this->Checked = false;
  this->Unsupported.clear();
}
}
