#include "vtkPenumbraGearsCompute.h"

#include "vtkOpenGLRenderWindow.h"
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

using penumbra_compute::GLErrorText;
using penumbra_compute::ProgramScope;
}

//------------------------------------------------------------------------------
MaskCompute::~MaskCompute() = default;

//------------------------------------------------------------------------------
bool MaskCompute::Prepare(
  vtkOpenGLRenderWindow* window, int k, int rows, bool keepMasks, std::string& why)
{
  if (k < 1 || k > 32 || rows < 1 || rows > 32)
  {
    why = "the compute path holds a mask row in 32 bits; " + std::to_string(k) +
      " light samples per row need the CPU path";
    return false;
  }
  if (!this->Device.Prepare(window, BufferCount, "GEARS", why))
  {
    return false;
  }
  if (this->Generation != this->Device.Generation())
  {
    // A new context: the programs and uploads of the old one are gone.
    this->Generation = this->Device.Generation();
    this->Programs.clear();
    this->Current = nullptr;
    this->CasterVersion = 0;
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
  unsigned int id = 0;
  if (!this->Device.Compile(source, id, why))
  {
    why = "GEARS: " + why;
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
    { &program.HasCasters, "uHasCasters" }, { &program.LoopProbe, "uLoopProbe" },
    { &program.Emitting, "uEmitting" } };
  for (const auto& u : uniforms)
  {
    *u.first = glGetUniformLocation(id, u.second);
  }
  return true;
}

//------------------------------------------------------------------------------
bool MaskCompute::SetCasters(
  const std::vector<double>& data, std::uint64_t version, std::string& why)
{
  if (version == this->CasterVersion && this->Device.Buffer(Casters))
  {
    return true;
  }
  if (!this->Device.Upload(Casters, data.data(), data.size() * sizeof(double), why))
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
  return this->Device.Upload(Positions, positions, 3 * n * sizeof(float), why) &&
    this->Device.Upload(Normals, normals, 3 * n * sizeof(float), why) &&
    this->Device.Upload(Owners, owners, n * sizeof(vtkIdType), why);
}

//------------------------------------------------------------------------------
bool MaskCompute::Run(const ComputeLight& light, const ComputeConstants& constants,
  const ComputeSide& side, std::vector<std::uint32_t>& results, std::vector<std::uint32_t>* masks,
  std::string& why)
{
  if (!this->Current || !this->Device.GetWindow())
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
  for (int binding : { Casters, Positions, Normals, Owners })
  {
    this->Device.Bind(binding);
  }
  if (!this->Device.Upload(ZNear, side.ZNear, this->CasterCount * sizeof(double), why) ||
    !this->Device.Upload(
      CellStart, side.CellStart, (side.Cells + 1) * sizeof(std::uint32_t), why) ||
    !this->Device.Upload(CellList, side.CellList, side.ListSize * sizeof(std::uint32_t), why) ||
    !this->Device.Upload(
      GlobalList, side.GlobalList, side.GlobalSize * sizeof(std::uint32_t), why) ||
    !this->Device.Upload(Work, side.Work, 2 * work * sizeof(std::uint32_t), why) ||
    !this->Device.Upload(LightPoints, light.Points, 3 * count * sizeof(double), why) ||
    !this->Device.Upload(Results, nullptr, 3 * work * sizeof(std::uint32_t), why) ||
    (masks && !this->Device.Upload(Masks, nullptr, masks->size() * sizeof(std::uint32_t), why)))
  {
    return false;
  }
  {
    ProgramScope scope(this->Device.GetWindow(), program.Id);
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
    glUniform1uiv(program.Emitting, light.Rows, light.Emitting);
    const std::size_t perDispatch = static_cast<std::size_t>(MaxGroups) * LocalSize;
    for (std::size_t offset = 0; offset < work; offset += perDispatch)
    {
      const std::size_t items = std::min(perDispatch, work - offset);
      glUniform1ui(program.WorkOffset, static_cast<GLuint>(offset));
      glDispatchCompute(static_cast<GLuint>((items + LocalSize - 1) / LocalSize), 1, 1);
    }
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, this->Device.Buffer(Results));
    glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0,
      static_cast<GLsizeiptr>(results.size() * sizeof(std::uint32_t)), results.data());
    if (masks)
    {
      glBindBuffer(GL_SHADER_STORAGE_BUFFER, this->Device.Buffer(Masks));
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
  if (window && vtkOpenGLRenderWindow::SafeDownCast(window) == this->Device.GetWindow())
  {
    this->Programs.clear();
    this->Current = nullptr;
    this->CasterVersion = 0;
  }
  this->Device.Release(window);
}
}
