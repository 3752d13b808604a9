#include "vtkPenumbraRoomSource.h"

#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraSourcesPrivate.h"
#include "vtkPolyData.h"

#include <algorithm>
#include <cmath>

using penumbra_sources::Vec3;

namespace
{
constexpr int MaxDivisions = 1024;

// The layout below is authored for this room and scaled to Size.
constexpr double ReferenceSize[3] = { 10.0, 10.0, 4.0 };

struct Box
{
  Vec3 Lo;
  Vec3 Hi;
  int PartId;
};

// Each object sits between the centre light (0, 0, 2) and the face it is meant to shadow,
// with a gap to that face so the shadow is visible rather than hidden behind the object.
const Box ReferenceBoxes[] = {
  // Table slab; the legs are added separately.
  { { -2.6, 0.6, 0.72 }, { -1.0, 1.5, 0.78 }, 1 },
  // Cabinet, 1 m in front of the +x wall: shadow on that wall up to ~2.6 m.
  { { 3.4, -1.2, 0.0 }, { 4.0, 0.4, 2.4 }, 2 },
  // Column from floor to ceiling, toward -x: full-height stripe on the -x wall.
  { { -3.4, -2.0, 0.0 }, { -3.0, -1.6, 4.0 }, 3 },
  // Shelf before the +y wall: shadow on that wall up to ~1.85 m.
  { { 0.5, 3.4, 0.0 }, { 2.3, 3.8, 1.9 }, 4 },
  // Wardrobe before the -y wall: shadow on that wall up to ~2.3 m.
  { { -2.2, -3.9, 0.0 }, { -0.8, -3.3, 2.2 }, 5 },
};

constexpr double TableLegSize = 0.06;
constexpr double TableLegInset = 0.05;

// Lamp shade above the light: shadows an annulus of the ceiling, r ~ 0.84..1.43 m.
constexpr int ShadePartId = 6;
constexpr double ShadeInnerRadius = 0.46;
constexpr double ShadeOuterRadius = 0.5;
constexpr double ShadeBottom = 2.7;
constexpr double ShadeTop = 3.1;
constexpr int ShadeSegments = 48;

int Divisions(double length, double cellSize)
{
  return std::clamp(static_cast<int>(std::ceil(length / cellSize)), 1, MaxDivisions);
}
}

vtkStandardNewMacro(vtkPenumbraRoomSource);

vtkPenumbraRoomSource::vtkPenumbraRoomSource()
  : Size{ 10.0, 10.0, 4.0 }
  , ShellCellSize(0.5)
  , GenerateFurniture(1)
{
  this->SetNumberOfInputPorts(0);
}

void vtkPenumbraRoomSource::GetLightPosition(double position[3])
{
  position[0] = 0.0;
  position[1] = 0.0;
  position[2] = 0.5 * this->Size[2];
}

int vtkPenumbraRoomSource::RequestData(vtkInformation* vtkNotUsed(request),
  vtkInformationVector** vtkNotUsed(inputVector), vtkInformationVector* outputVector)
{
  vtkPolyData* output = vtkPolyData::GetData(outputVector);
  output->Initialize();

  for (int i = 0; i < 3; ++i)
  {
    if (!std::isfinite(this->Size[i]) || this->Size[i] <= 0.0)
    {
      vtkErrorMacro("Size must be finite and > 0 m on every axis, got ("
        << this->Size[0] << ", " << this->Size[1] << ", " << this->Size[2] << ")");
      return 0;
    }
  }
  if (!std::isfinite(this->ShellCellSize) || this->ShellCellSize <= 0.0)
  {
    vtkErrorMacro("ShellCellSize must be a finite length > 0 m, got " << this->ShellCellSize);
    return 0;
  }

  penumbra_sources::MeshBuilder mesh;
  const double hx = 0.5 * this->Size[0];
  const double hy = 0.5 * this->Size[1];
  const double h = this->Size[2];
  const double c = this->ShellCellSize;
  const int nx = Divisions(this->Size[0], c);
  const int ny = Divisions(this->Size[1], c);
  const int nz = Divisions(this->Size[2], c);

  const Vec3 alongX = { 2 * hx, 0, 0 };
  const Vec3 alongY = { 0, 2 * hy, 0 };
  const Vec3 alongZ = { 0, 0, h };
  mesh.AddGrid({ -hx, -hy, 0 }, alongX, alongY, nx, ny, { 0, 0, 1 }, 0);  // floor
  mesh.AddGrid({ -hx, -hy, h }, alongX, alongY, nx, ny, { 0, 0, -1 }, 0); // ceiling
  mesh.AddGrid({ -hx, -hy, 0 }, alongY, alongZ, ny, nz, { 1, 0, 0 }, 0);  // -x wall
  mesh.AddGrid({ hx, -hy, 0 }, alongY, alongZ, ny, nz, { -1, 0, 0 }, 0);  // +x wall
  mesh.AddGrid({ -hx, -hy, 0 }, alongX, alongZ, nx, nz, { 0, 1, 0 }, 0);  // -y wall
  mesh.AddGrid({ -hx, hy, 0 }, alongX, alongZ, nx, nz, { 0, -1, 0 }, 0);  // +y wall

  if (this->GenerateFurniture)
  {
    const Vec3 scale = { this->Size[0] / ReferenceSize[0], this->Size[1] / ReferenceSize[1],
      this->Size[2] / ReferenceSize[2] };
    auto scaled = [&scale](const Vec3& p) {
      return Vec3{ p[0] * scale[0], p[1] * scale[1], p[2] * scale[2] };
    };

    for (const Box& box : ReferenceBoxes)
    {
      mesh.AddBox(scaled(box.Lo), scaled(box.Hi), box.PartId);
    }

    const Box& slab = ReferenceBoxes[0];
    for (const double x : { slab.Lo[0] + TableLegInset, slab.Hi[0] - TableLegInset - TableLegSize })
    {
      for (const double y :
        { slab.Lo[1] + TableLegInset, slab.Hi[1] - TableLegInset - TableLegSize })
      {
        mesh.AddBox(scaled({ x, y, 0.0 }),
          scaled({ x + TableLegSize, y + TableLegSize, slab.Lo[2] }), slab.PartId);
      }
    }

    // Closed (both walls and both annuli) so the shade looks solid from below and casts the
    // same shadow whichever faces a renderer culls.
    const double r = std::min(scale[0], scale[1]);
    const double ri = ShadeInnerRadius * r, ro = ShadeOuterRadius * r;
    const double z0 = ShadeBottom * scale[2], z1 = ShadeTop * scale[2];
    mesh.AddCylinderWall(0, 0, ro, z0, z1, ShadeSegments, false, ShadePartId);
    mesh.AddCylinderWall(0, 0, ri, z0, z1, ShadeSegments, true, ShadePartId);
    mesh.AddAnnulus(0, 0, ri, ro, z1, ShadeSegments, true, ShadePartId);
    mesh.AddAnnulus(0, 0, ri, ro, z0, ShadeSegments, false, ShadePartId);
  }

  mesh.Finish(output);
  return 1;
}

void vtkPenumbraRoomSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Size: (" << this->Size[0] << ", " << this->Size[1] << ", " << this->Size[2]
     << ")\n";
  os << indent << "ShellCellSize: " << this->ShellCellSize << "\n";
  os << indent << "GenerateFurniture: " << (this->GenerateFurniture ? "On" : "Off") << "\n";
}
