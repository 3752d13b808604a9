#include "vtkPenumbraSourcesPrivate.h"

#include "vtkAlgorithm.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkExecutive.h"
#include "vtkFloatArray.h"
#include "vtkIntArray.h"
#include "vtkMath.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <glm/geometric.hpp>

#include <cmath>

namespace penumbra_sources
{
namespace
{
// a / |a|, or zero for a zero vector (glm::normalize would divide by zero).
Vec3 Normalized(const Vec3& a)
{
  const double len = glm::length(a);
  return len == 0.0 ? Vec3(0.0) : a / len;
}

// Keeps only "message" out of VTK's "ERROR: In file, line N\nclass (0x...): message\n\n".
std::string StripVTKPrefix(const char* text)
{
  std::string s = text ? text : "";
  const auto eol = s.find('\n');
  if (eol != std::string::npos)
  {
    const auto colon = s.find("): ", eol);
    if (colon != std::string::npos)
    {
      s = s.substr(colon + 3);
    }
  }
  while (!s.empty() && (s.back() == '\n' || s.back() == ' '))
  {
    s.pop_back();
  }
  return s;
}
}

double UniformUnit(std::mt19937& rng)
{
  const std::uint32_t a = static_cast<std::uint32_t>(rng()) >> 5; // 27 bits
  const std::uint32_t b = static_cast<std::uint32_t>(rng()) >> 6; // 26 bits
  return (a * 67108864.0 + b) * (1.0 / 9007199254740992.0);
}

bool IsFinite(double v)
{
  return std::isfinite(v);
}

bool AllFinite(const double* v, int n)
{
  for (int i = 0; i < n; ++i)
  {
    if (!std::isfinite(v[i]))
    {
      return false;
    }
  }
  return true;
}

MeshBuilder::MeshBuilder(const double offset[3])
  : Offset{ 0.0, 0.0, 0.0 }
{
  if (offset)
  {
    this->Offset = { offset[0], offset[1], offset[2] };
  }
  this->Points->SetDataTypeToDouble();
  this->Normals->SetName("Normals");
  this->Normals->SetNumberOfComponents(3);
  this->PartIds->SetName("PartId");
  this->PartIds->SetNumberOfComponents(1);
}

MeshBuilder::~MeshBuilder() = default;

vtkIdType MeshBuilder::InsertPoint(const Vec3& p, const Vec3& n)
{
  const vtkIdType id = this->Points->InsertNextPoint(
    p[0] + this->Offset[0], p[1] + this->Offset[1], p[2] + this->Offset[2]);
  const float nf[3] = { static_cast<float>(n[0]), static_cast<float>(n[1]),
    static_cast<float>(n[2]) };
  this->Normals->InsertNextTypedTuple(nf);
  return id;
}

void MeshBuilder::InsertTriangle(vtkIdType a, vtkIdType b, vtkIdType c, int partId)
{
  const vtkIdType ids[3] = { a, b, c };
  this->Polys->InsertNextCell(3, ids);
  this->PartIds->InsertNextValue(partId);
}

void MeshBuilder::AddPolygon(const Vec3* corners, int count, const Vec3& facing, int partId)
{
  if (count < 3 || count > 4)
  {
    return;
  }
  // For a convex quad the diagonal cross product is a robust (area-weighted) normal.
  const Vec3 geometric = count == 3 ? glm::cross(corners[1] - corners[0], corners[2] - corners[0])
                                    : glm::cross(corners[2] - corners[0], corners[3] - corners[1]);
  const bool flip = glm::dot(geometric, facing) < 0.0;
  const Vec3 n = Normalized(flip ? -geometric : geometric);

  vtkIdType ids[4];
  for (int i = 0; i < count; ++i)
  {
    ids[i] = this->InsertPoint(corners[flip ? count - 1 - i : i], n);
  }
  this->InsertTriangle(ids[0], ids[1], ids[2], partId);
  if (count == 4)
  {
    this->InsertTriangle(ids[0], ids[2], ids[3], partId);
  }
}

void MeshBuilder::AddGrid(
  const Vec3& origin, const Vec3& u, const Vec3& v, int nu, int nv, const Vec3& facing, int partId)
{
  Vec3 n = glm::cross(u, v);
  const bool flip = glm::dot(n, facing) < 0.0;
  if (flip)
  {
    n = -n;
  }
  n = Normalized(n);

  const vtkIdType first = this->Points->GetNumberOfPoints();
  for (int j = 0; j <= nv; ++j)
  {
    const double t = static_cast<double>(j) / nv;
    for (int i = 0; i <= nu; ++i)
    {
      const double s = static_cast<double>(i) / nu;
      this->InsertPoint({ origin[0] + s * u[0] + t * v[0], origin[1] + s * u[1] + t * v[1],
                          origin[2] + s * u[2] + t * v[2] },
        n);
    }
  }
  for (int j = 0; j < nv; ++j)
  {
    for (int i = 0; i < nu; ++i)
    {
      const vtkIdType p00 = first + static_cast<vtkIdType>(j) * (nu + 1) + i;
      const vtkIdType p10 = p00 + 1;
      const vtkIdType p01 = p00 + nu + 1;
      const vtkIdType p11 = p01 + 1;
      if (flip)
      {
        this->InsertTriangle(p00, p01, p11, partId);
        this->InsertTriangle(p00, p11, p10, partId);
      }
      else
      {
        this->InsertTriangle(p00, p10, p11, partId);
        this->InsertTriangle(p00, p11, p01, partId);
      }
    }
  }
}

void MeshBuilder::AddBox(const Vec3& lo, const Vec3& hi, int partId)
{
  const Vec3 c[8] = {
    { lo[0], lo[1], lo[2] },
    { hi[0], lo[1], lo[2] },
    { hi[0], hi[1], lo[2] },
    { lo[0], hi[1], lo[2] },
    { lo[0], lo[1], hi[2] },
    { hi[0], lo[1], hi[2] },
    { hi[0], hi[1], hi[2] },
    { lo[0], hi[1], hi[2] },
  };
  const Vec3 bottom[4] = { c[0], c[1], c[2], c[3] };
  const Vec3 top[4] = { c[4], c[5], c[6], c[7] };
  const Vec3 south[4] = { c[0], c[1], c[5], c[4] };
  const Vec3 north[4] = { c[3], c[2], c[6], c[7] };
  const Vec3 west[4] = { c[0], c[3], c[7], c[4] };
  const Vec3 east[4] = { c[1], c[2], c[6], c[5] };
  this->AddPolygon(bottom, 4, { 0, 0, -1 }, partId);
  this->AddPolygon(top, 4, { 0, 0, 1 }, partId);
  this->AddPolygon(south, 4, { 0, -1, 0 }, partId);
  this->AddPolygon(north, 4, { 0, 1, 0 }, partId);
  this->AddPolygon(west, 4, { -1, 0, 0 }, partId);
  this->AddPolygon(east, 4, { 1, 0, 0 }, partId);
}

void MeshBuilder::AddCylinderWall(
  double cx, double cy, double r, double z0, double z1, int segments, bool towardAxis, int partId)
{
  const double sign = towardAxis ? -1.0 : 1.0;
  const vtkIdType first = this->Points->GetNumberOfPoints();
  for (int i = 0; i < segments; ++i)
  {
    const double a = 2.0 * vtkMath::Pi() * i / segments;
    const Vec3 n = { sign * std::cos(a), sign * std::sin(a), 0.0 };
    this->InsertPoint({ cx + r * std::cos(a), cy + r * std::sin(a), z0 }, n);
    this->InsertPoint({ cx + r * std::cos(a), cy + r * std::sin(a), z1 }, n);
  }
  for (int i = 0; i < segments; ++i)
  {
    const int k = (i + 1) % segments;
    const vtkIdType b0 = first + 2 * i, t0 = b0 + 1;
    const vtkIdType b1 = first + 2 * k, t1 = b1 + 1;
    // Counter-clockwise seen from outside when the normal points away from the axis.
    if (towardAxis)
    {
      this->InsertTriangle(b0, t1, b1, partId);
      this->InsertTriangle(b0, t0, t1, partId);
    }
    else
    {
      this->InsertTriangle(b0, b1, t1, partId);
      this->InsertTriangle(b0, t1, t0, partId);
    }
  }
}

void MeshBuilder::AddAnnulus(
  double cx, double cy, double r0, double r1, double z, int segments, bool up, int partId)
{
  const Vec3 n = { 0.0, 0.0, up ? 1.0 : -1.0 };
  const vtkIdType first = this->Points->GetNumberOfPoints();
  for (int i = 0; i < segments; ++i)
  {
    const double a = 2.0 * vtkMath::Pi() * i / segments;
    this->InsertPoint({ cx + r0 * std::cos(a), cy + r0 * std::sin(a), z }, n);
    this->InsertPoint({ cx + r1 * std::cos(a), cy + r1 * std::sin(a), z }, n);
  }
  for (int i = 0; i < segments; ++i)
  {
    const int k = (i + 1) % segments;
    const vtkIdType i0 = first + 2 * i, o0 = i0 + 1;
    const vtkIdType i1 = first + 2 * k, o1 = i1 + 1;
    // Counter-clockwise seen from +z.
    if (up)
    {
      this->InsertTriangle(i0, o0, o1, partId);
      this->InsertTriangle(i0, o1, i1, partId);
    }
    else
    {
      this->InsertTriangle(i0, o1, o0, partId);
      this->InsertTriangle(i0, i1, o1, partId);
    }
  }
}

vtkIdType MeshBuilder::GetNumberOfCells() const
{
  return this->Polys->GetNumberOfCells();
}

void MeshBuilder::Finish(vtkPolyData* output)
{
  output->Initialize();
  output->SetPoints(this->Points);
  output->SetPolys(this->Polys);
  output->GetPointData()->SetNormals(this->Normals);
  output->GetCellData()->AddArray(this->PartIds);
  output->GetCellData()->SetActiveScalars("PartId");
  output->Squeeze();
}

void MessageCollector::Execute(vtkObject* caller, unsigned long event, void* callData)
{
  std::string text = StripVTKPrefix(static_cast<const char*>(callData));
  // Executives only add "returned failure for request" and an information dump: keep the
  // first line, and only as a fallback when the algorithm said nothing itself.
  const bool fromExecutive = vtkExecutive::SafeDownCast(caller) != nullptr;
  if (fromExecutive)
  {
    text = text.substr(0, text.find('\n'));
  }
  std::string& sink = event != vtkCommand::ErrorEvent
    ? this->Warnings
    : (fromExecutive ? this->ExecutiveErrors : this->Errors);
  // Readers often repeat a message in RequestInformation and RequestData.
  if (text.empty() || sink.find(text) != std::string::npos)
  {
    return;
  }
  if (!sink.empty())
  {
    sink += "; ";
  }
  sink += text;
}

void MessageCollector::Watch(vtkAlgorithm* algorithm)
{
  algorithm->AddObserver(vtkCommand::ErrorEvent, this);
  algorithm->AddObserver(vtkCommand::WarningEvent, this);
  algorithm->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, this);
  algorithm->GetExecutive()->AddObserver(vtkCommand::WarningEvent, this);
}
}
