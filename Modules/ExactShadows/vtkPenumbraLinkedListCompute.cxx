#include "vtkPenumbraLinkedListCompute.h"

#include "vtkOpenGLRenderWindow.h"
#include "vtk_glew.h"

#include "vtkPenumbraLinkedListBuildCS.h"

#include <algorithm>

namespace penumbra_llsm
{
namespace
{
constexpr unsigned int LocalSize = 64;    // local_size_x of the shader
constexpr unsigned int MaxGroups = 65535; // GL 4.3's guaranteed work-group count per axis

// Storage binding points of the shader.
enum Binding
{
  ItemBuffer,
  HeadBuffer,
  NodeBuffer,
  CounterBuffer,
  BindingCount
};
}

//------------------------------------------------------------------------------
bool ListCompute::Prepare(vtkOpenGLRenderWindow* window, std::string& why)
{
  if (!this->Device.Prepare(window, BindingCount, "LLSM list", why))
  {
    return false;
  }
  if (this->Generation != this->Device.Generation())
  {
    this->Generation = this->Device.Generation();
    this->Program = 0;
    this->HeadTexels = 0;
  }
  if (!this->Program)
  {
    const std::string source = "#version 430\n#define LLSM_LOCAL_SIZE " +
      std::to_string(LocalSize) + "\n" + vtkPenumbraLinkedListBuildCS;
    if (!this->Device.Compile(source, this->Program, why))
    {
      why = "LLSM lists: " + why;
      return false;
    }
    const std::pair<int*, const char*> uniforms[] = { { &this->Offset, "uOffset" },
      { &this->Count, "uCount" }, { &this->Capacity, "uCapacity" }, { &this->Reset, "uReset" } };
    for (const auto& u : uniforms)
    {
      *u.first = glGetUniformLocation(this->Program, u.second);
    }
  }
  return true;
}

//------------------------------------------------------------------------------
bool ListCompute::Dispatch(std::size_t count, bool reset, std::string& why)
{
  {
    penumbra_compute::ProgramScope scope(this->Device.GetWindow(), this->Program);
    for (int binding = 0; binding < BindingCount; ++binding)
    {
      this->Device.Bind(binding);
    }
    glUniform1ui(this->Count, static_cast<GLuint>(count));
    glUniform1i(this->Reset, reset ? 1 : 0);
    const std::size_t perDispatch = static_cast<std::size_t>(MaxGroups) * LocalSize;
    for (std::size_t offset = 0; offset < count; offset += perDispatch)
    {
      const std::size_t n = std::min(perDispatch, count - offset);
      glUniform1ui(this->Offset, static_cast<GLuint>(offset));
      glDispatchCompute(static_cast<GLuint>((n + LocalSize - 1) / LocalSize), 1, 1);
    }
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  }
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR)
  {
    why = "the LLSM list dispatch failed: " + penumbra_compute::GLErrorText(error);
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
bool ListCompute::Link(const std::uint32_t* items, std::size_t count, std::size_t texels,
  std::size_t capacity, std::vector<std::uint32_t>& nodes, std::uint32_t& requested,
  std::string& why)
{
  nodes.clear();
  requested = 0;
  if (!this->Program)
  {
    why = "the LLSM list path was not prepared";
    return false;
  }
  if (texels != this->HeadTexels || this->Linked)
  {
    // A new head image (or one a failed call left dirty): every head empty.
    this->HeadTexels = 0;
    if (!this->Device.Upload(HeadBuffer, nullptr, texels * sizeof(std::uint32_t), why))
    {
      return false;
    }
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, this->Device.Buffer(HeadBuffer));
    const GLuint empty = NoNode;
    glClearBufferSubData(GL_SHADER_STORAGE_BUFFER, GL_R32UI, 0,
      static_cast<GLsizeiptr>(texels * sizeof(std::uint32_t)), GL_RED_INTEGER, GL_UNSIGNED_INT,
      &empty);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
    this->HeadTexels = texels;
  }
  const std::uint32_t zero = 0;
  if (!this->Device.Upload(ItemBuffer, items, 2 * count * sizeof(std::uint32_t), why) ||
    !this->Device.Upload(NodeBuffer, nullptr, 2 * capacity * sizeof(std::uint32_t), why) ||
    !this->Device.Upload(CounterBuffer, &zero, sizeof(zero), why))
  {
    return false;
  }
  this->Items = count;
  this->Linked = true;
  {
    penumbra_compute::ProgramScope scope(this->Device.GetWindow(), this->Program);
    glUniform1ui(this->Capacity, static_cast<GLuint>(capacity));
  }
  if (!this->Dispatch(count, false, why) ||
    !this->Device.Download(CounterBuffer, &requested, sizeof(requested), why))
  {
    return false;
  }
  nodes.resize(2 * std::min<std::size_t>(requested, capacity));
  return this->Device.Download(NodeBuffer, nodes.data(), nodes.size() * sizeof(std::uint32_t), why);
}

//------------------------------------------------------------------------------
bool ListCompute::Heads(
  const std::vector<std::uint32_t>& texels, std::vector<std::uint32_t>& heads, std::string& why)
{
  heads.resize(texels.size());
  if (!this->Linked)
  {
    why = "no LLSM lists to read";
    return false;
  }
  if (!texels.empty())
  {
    // Mapped, not copied: only the heads of texels with lists are read.
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, this->Device.Buffer(HeadBuffer));
    const auto* mapped =
      static_cast<const std::uint32_t*>(glMapBufferRange(GL_SHADER_STORAGE_BUFFER, 0,
        static_cast<GLsizeiptr>(this->HeadTexels * sizeof(std::uint32_t)), GL_MAP_READ_BIT));
    if (!mapped)
    {
      glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
      why = "the LLSM head image cannot be mapped: " + penumbra_compute::GLErrorText(glGetError());
      return false;
    }
    for (std::size_t i = 0; i < texels.size(); ++i)
    {
      heads[i] = texels[i] < this->HeadTexels ? mapped[texels[i]] : NoNode;
    }
    glUnmapBuffer(GL_SHADER_STORAGE_BUFFER);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
  }
  // Empty the linked heads again for the next pass.
  if (!this->Dispatch(this->Items, true, why))
  {
    return false;
  }
  this->Linked = false;
  return true;
}

//------------------------------------------------------------------------------
void ListCompute::Release(vtkWindow* window)
{
  if (window && vtkOpenGLRenderWindow::SafeDownCast(window) == this->Device.GetWindow())
  {
    this->Program = 0;
    this->HeadTexels = 0;
    this->Linked = false;
  }
  this->Device.Release(window);
}
}
