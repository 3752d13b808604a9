#include "vtkPenumbraCityBlockSource.h"

#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMath.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraSourcesPrivate.h"
#include "vtkPolyData.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

using penumbra_sources::Vec3;

namespace
{
// Caps memory for absurd inputs (1e6 lots is already ~16M triangles).
constexpr double MaxLots = 1.0e6;
// Ground quads per axis; a huge GroundMargin then gives bigger quads instead of an
// unbounded mesh.
constexpr int MaxGroundDivisions = 1024;

// Gable-roofed building: walls up to the eaves, two sloped roof faces meeting at a ridge
// along the longer side, and triangular gable ends.
void AddGableBuilding(
  penumbra_sources::MeshBuilder& mesh, const Vec3& lo, const Vec3& hi, double eave, int partId)
{
  const double x0 = lo[0], y0 = lo[1], x1 = hi[0], y1 = hi[1], top = hi[2];
  const bool ridgeAlongX = (x1 - x0) >= (y1 - y0);

  const Vec3 bottom[4] = { { x0, y0, 0 }, { x1, y0, 0 }, { x1, y1, 0 }, { x0, y1, 0 } };
  mesh.AddPolygon(bottom, 4, { 0, 0, -1 }, partId);

  if (ridgeAlongX)
  {
    const double ym = 0.5 * (y0 + y1);
    const Vec3 south[4] = { { x0, y0, 0 }, { x1, y0, 0 }, { x1, y0, eave }, { x0, y0, eave } };
    const Vec3 north[4] = { { x0, y1, 0 }, { x1, y1, 0 }, { x1, y1, eave }, { x0, y1, eave } };
    mesh.AddPolygon(south, 4, { 0, -1, 0 }, partId);
    mesh.AddPolygon(north, 4, { 0, 1, 0 }, partId);
    for (const double x : { x0, x1 })
    {
      const Vec3 facing = { x == x0 ? -1.0 : 1.0, 0, 0 };
      const Vec3 wall[4] = { { x, y0, 0 }, { x, y1, 0 }, { x, y1, eave }, { x, y0, eave } };
      const Vec3 gable[3] = { { x, y0, eave }, { x, y1, eave }, { x, ym, top } };
      mesh.AddPolygon(wall, 4, facing, partId);
      mesh.AddPolygon(gable, 3, facing, partId);
    }
    const Vec3 roofS[4] = { { x0, y0, eave }, { x1, y0, eave }, { x1, ym, top }, { x0, ym, top } };
    const Vec3 roofN[4] = { { x0, y1, eave }, { x1, y1, eave }, { x1, ym, top }, { x0, ym, top } };
    mesh.AddPolygon(roofS, 4, { 0, -(top - eave), ym - y0 }, partId);
    mesh.AddPolygon(roofN, 4, { 0, top - eave, y1 - ym }, partId);
  }
  else
  {
    const double xm = 0.5 * (x0 + x1);
    const Vec3 west[4] = { { x0, y0, 0 }, { x0, y1, 0 }, { x0, y1, eave }, { x0, y0, eave } };
    const Vec3 east[4] = { { x1, y0, 0 }, { x1, y1, 0 }, { x1, y1, eave }, { x1, y0, eave } };
    mesh.AddPolygon(west, 4, { -1, 0, 0 }, partId);
    mesh.AddPolygon(east, 4, { 1, 0, 0 }, partId);
    for (const double y : { y0, y1 })
    {
      const Vec3 facing = { 0, y == y0 ? -1.0 : 1.0, 0 };
      const Vec3 wall[4] = { { x0, y, 0 }, { x1, y, 0 }, { x1, y, eave }, { x0, y, eave } };
      const Vec3 gable[3] = { { x0, y, eave }, { x1, y, eave }, { xm, y, top } };
      mesh.AddPolygon(wall, 4, facing, partId);
      mesh.AddPolygon(gable, 3, facing, partId);
    }
    const Vec3 roofW[4] = { { x0, y0, eave }, { x0, y1, eave }, { xm, y1, top }, { xm, y0, top } };
    const Vec3 roofE[4] = { { x1, y0, eave }, { x1, y1, eave }, { xm, y1, top }, { xm, y0, top } };
    mesh.AddPolygon(roofW, 4, { -(top - eave), 0, xm - x0 }, partId);
    mesh.AddPolygon(roofE, 4, { top - eave, 0, x1 - xm }, partId);
  }
}
}

vtkStandardNewMacro(vtkPenumbraCityBlockSource);

vtkPenumbraCityBlockSource::vtkPenumbraCityBlockSource()
  : Rows(4)
  , Columns(4)
  , Spacing(30.0)
  , FootprintMin(0.4)
  , FootprintMax(0.8)
  , MinHeight(8.0)
  , MaxHeight(40.0)
  , GableRoofFraction(0.25)
  , GableRoofPitch(30.0)
  , Seed(1)
  , GenerateGround(1)
  , GroundMargin(20.0)
  , Origin{ 0.0, 0.0, 0.0 }
{
  this->SetNumberOfInputPorts(0);
}

bool vtkPenumbraCityBlockSource::CheckParameters()
{
  using penumbra_sources::IsFinite;
  if (this->Rows < 1 || this->Columns < 1)
  {
    vtkErrorMacro(
      "Rows and Columns must be >= 1, got Rows=" << this->Rows << " Columns=" << this->Columns);
    return false;
  }
  if (static_cast<double>(this->Rows) * this->Columns > MaxLots)
  {
    vtkErrorMacro(
      "Rows*Columns must be <= " << MaxLots << ", got " << this->Rows << "*" << this->Columns);
    return false;
  }
  if (!IsFinite(this->Spacing) || this->Spacing <= 0.0)
  {
    vtkErrorMacro("Spacing must be a finite length > 0 m, got " << this->Spacing);
    return false;
  }
  if (!IsFinite(this->FootprintMin) || !IsFinite(this->FootprintMax) ||
    !(this->FootprintMin > 0.0) || !(this->FootprintMin <= this->FootprintMax) ||
    !(this->FootprintMax <= 1.0))
  {
    vtkErrorMacro("Footprint fractions must satisfy 0 < FootprintMin <= FootprintMax <= 1, got "
      << this->FootprintMin << " and " << this->FootprintMax);
    return false;
  }
  if (!IsFinite(this->MinHeight) || !IsFinite(this->MaxHeight) || !(this->MinHeight > 0.0) ||
    !(this->MinHeight <= this->MaxHeight))
  {
    vtkErrorMacro("Heights must be finite with 0 < MinHeight <= MaxHeight, got MinHeight="
      << this->MinHeight << " m, MaxHeight=" << this->MaxHeight << " m");
    return false;
  }
  if (!(this->GableRoofFraction >= 0.0 && this->GableRoofFraction <= 1.0))
  {
    vtkErrorMacro("GableRoofFraction must be in [0, 1], got " << this->GableRoofFraction);
    return false;
  }
  if (!(this->GableRoofPitch > 0.0 && this->GableRoofPitch < 90.0))
  {
    vtkErrorMacro("GableRoofPitch must be in (0, 90) degrees, got " << this->GableRoofPitch);
    return false;
  }
  if (!IsFinite(this->GroundMargin) || this->GroundMargin < 0.0)
  {
    vtkErrorMacro("GroundMargin must be a finite length >= 0 m, got " << this->GroundMargin);
    return false;
  }
  if (!penumbra_sources::AllFinite(this->Origin, 3))
  {
    vtkErrorMacro("Origin must be finite, got (" << this->Origin[0] << ", " << this->Origin[1]
                                                 << ", " << this->Origin[2] << ")");
    return false;
  }
  return true;
}

int vtkPenumbraCityBlockSource::RequestData(vtkInformation* vtkNotUsed(request),
  vtkInformationVector** vtkNotUsed(inputVector), vtkInformationVector* outputVector)
{
  vtkPolyData* output = vtkPolyData::GetData(outputVector);
  output->Initialize();
  if (!this->CheckParameters())
  {
    return 0;
  }

  penumbra_sources::MeshBuilder mesh(this->Origin);
  const double s = this->Spacing;
  const double width = this->Columns * s;
  const double depth = this->Rows * s;

  if (this->GenerateGround)
  {
    const double m = this->GroundMargin;
    const int nu =
      std::clamp(static_cast<int>(std::ceil((width + 2 * m) / s)), 1, MaxGroundDivisions);
    const int nv =
      std::clamp(static_cast<int>(std::ceil((depth + 2 * m) / s)), 1, MaxGroundDivisions);
    mesh.AddGrid({ -m, -m, 0.0 }, { width + 2 * m, 0.0, 0.0 }, { 0.0, depth + 2 * m, 0.0 }, nu, nv,
      { 0, 0, 1 }, 0);
  }

  std::mt19937 rng(static_cast<std::uint32_t>(this->Seed));
  const double tanPitch = std::tan(vtkMath::RadiansFromDegrees(this->GableRoofPitch));
  for (int row = 0; row < this->Rows; ++row)
  {
    for (int col = 0; col < this->Columns; ++col)
    {
      // Always the same six draws per lot, so changing e.g. GableRoofFraction does not
      // reshuffle the footprints and heights of every later building.
      const double uw = penumbra_sources::UniformUnit(rng);
      const double ud = penumbra_sources::UniformUnit(rng);
      const double ux = penumbra_sources::UniformUnit(rng);
      const double uy = penumbra_sources::UniformUnit(rng);
      const double uh = penumbra_sources::UniformUnit(rng);
      const double ug = penumbra_sources::UniformUnit(rng);

      const double range = this->FootprintMax - this->FootprintMin;
      const double w = s * (this->FootprintMin + uw * range);
      const double d = s * (this->FootprintMin + ud * range);
      // Jitter within the middle half of the slack keeps a street between neighbours.
      const double x0 = col * s + (s - w) * (0.25 + 0.5 * ux);
      const double y0 = row * s + (s - d) * (0.25 + 0.5 * uy);
      const double height = this->MinHeight + uh * (this->MaxHeight - this->MinHeight);
      const int partId = row * this->Columns + col + 1;

      const Vec3 lo = { x0, y0, 0.0 };
      const Vec3 hi = { x0 + w, y0 + d, height };
      if (ug < this->GableRoofFraction)
      {
        const double rise = std::min(0.5 * std::min(w, d) * tanPitch, 0.5 * height);
        AddGableBuilding(mesh, lo, hi, height - rise, partId);
      }
      else
      {
        mesh.AddBox(lo, hi, partId);
      }
    }
  }

  mesh.Finish(output);
  return 1;
}

void vtkPenumbraCityBlockSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Rows: " << this->Rows << "\n";
  os << indent << "Columns: " << this->Columns << "\n";
  os << indent << "Spacing: " << this->Spacing << "\n";
  os << indent << "FootprintMin: " << this->FootprintMin << "\n";
  os << indent << "FootprintMax: " << this->FootprintMax << "\n";
  os << indent << "MinHeight: " << this->MinHeight << "\n";
  os << indent << "MaxHeight: " << this->MaxHeight << "\n";
  os << indent << "GableRoofFraction: " << this->GableRoofFraction << "\n";
  os << indent << "GableRoofPitch: " << this->GableRoofPitch << "\n";
  os << indent << "Seed: " << this->Seed << "\n";
  os << indent << "GenerateGround: " << (this->GenerateGround ? "On" : "Off") << "\n";
  os << indent << "GroundMargin: " << this->GroundMargin << "\n";
  os << indent << "Origin: (" << this->Origin[0] << ", " << this->Origin[1] << ", "
     << this->Origin[2] << ")\n";
}
