#include "vtkPenumbraAreaLight.h"

#include "vtkDoubleArray.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkObjectFactory.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

vtkStandardNewMacro(vtkPenumbraAreaLight);

vtkPenumbraAreaLight::vtkPenumbraAreaLight()
  : Shape(Rectangle)
  , Width(1.0)
  , Height(1.0)
  , Up{ 0.0, 0.0, 1.0 }
  , SamplesPerAxis(8)
  , ValidityMessage{ 0 }
{
  // Shade like a point light at the centre when no soft-shadow technique runs.
  this->SetPositional(true);
  this->SetConeAngle(180.0);
  this->SetLightTypeToSceneLight();
}

int vtkPenumbraAreaLight::GetNumberOfSamples()
{
  if (this->Shape != Disc)
  {
    return this->Shape == Line ? this->SamplesPerAxis : this->SamplesPerAxis * this->SamplesPerAxis;
  }
  int count = 0;
  for (int j = 0; j < this->SamplesPerAxis; ++j)
  {
    int first, last;
    count += this->RowCells(this->SamplesPerAxis, j, first, last) ? last - first + 1 : 0;
  }
  return count;
}

double vtkPenumbraAreaLight::GetExtentV() const
{
  return this->Shape == Line ? 0.0 : (this->Shape == Disc ? this->Width : this->Height);
}

int vtkPenumbraAreaLight::GetNumberOfRows()
{
  return this->Shape == Line ? 1 : this->SamplesPerAxis;
}

const char* vtkPenumbraAreaLight::GetShapeAsString()
{
  return this->Shape == Line ? "Line" : (this->Shape == Disc ? "Disc" : "Rectangle");
}

bool vtkPenumbraAreaLight::RowCells(int k, int row, int& first, int& last) const
{
  first = 0;
  last = k - 1;
  if (row < 0 || row >= (this->Shape == Line ? 1 : k))
  {
    first = 1;
    last = 0;
    return false;
  }
  if (this->Shape != Disc)
  {
    return true;
  }
  // Cell centres in units of the diameter; kept when inside the disc of radius 1/2. The
  // kept cells of a row are contiguous and symmetric about the centre column.
  const double sv = (row + 0.5) / k - 0.5;
  first = k;
  last = -1;
  for (int i = 0; i < k; ++i)
  {
    const double su = (i + 0.5) / k - 0.5;
    if (su * su + sv * sv <= 0.25)
    {
      first = std::min(first, i);
      last = std::max(last, i);
    }
  }
  return first <= last;
}

bool vtkPenumbraAreaLight::GetRowCells(int row, int& first, int& last)
{
  return this->RowCells(this->SamplesPerAxis, row, first, last);
}

void vtkPenumbraAreaLight::CellPosition(int k, int i, int j, const double centre[3],
  const double u[3], const double v[3], double position[3]) const
{
  const double su = ((i + 0.5) / k - 0.5) * this->Width;
  const double sv = this->Shape == Line ? 0.0 : ((j + 0.5) / k - 0.5) * this->GetExtentV();
  for (int c = 0; c < 3; ++c)
  {
    position[c] = centre[c] + su * u[c] + sv * v[c];
  }
}

void vtkPenumbraAreaLight::GetCentre(double centre[3])
{
  this->GetTransformedPosition(centre);
}

bool vtkPenumbraAreaLight::GetAxes(double u[3], double v[3], double n[3])
{
  // World frame: position and focal point through the TransformMatrix (when set), Up as a
  // direction through its rotation.
  double position[3], focal[3];
  this->GetTransformedPosition(position);
  this->GetTransformedFocalPoint(focal);
  for (int c = 0; c < 3; ++c)
  {
    n[c] = focal[c] - position[c];
  }
  if (vtkMath::Normalize(n) == 0.0)
  {
    return false;
  }
  // V = Up made perpendicular to N; fall back to the world axis least aligned with N.
  double up[3] = { this->Up[0], this->Up[1], this->Up[2] };
  if (vtkMatrix4x4* m = this->GetTransformMatrix())
  {
    double d[4] = { up[0], up[1], up[2], 0.0 };
    m->MultiplyPoint(d, d);
    std::copy(d, d + 3, up);
  }
  double along = vtkMath::Dot(up, n);
  double w[3] = { up[0] - along * n[0], up[1] - along * n[1], up[2] - along * n[2] };
  if (vtkMath::Norm(w) < 1e-9 * std::max(1.0, vtkMath::Norm(up)))
  {
    int axis = 0;
    for (int c = 1; c < 3; ++c)
    {
      if (std::fabs(n[c]) < std::fabs(n[axis]))
      {
        axis = c;
      }
    }
    double e[3] = { 0, 0, 0 };
    e[axis] = 1.0;
    along = vtkMath::Dot(e, n);
    for (int c = 0; c < 3; ++c)
    {
      w[c] = e[c] - along * n[c];
    }
  }
  vtkMath::Normalize(w);
  for (int c = 0; c < 3; ++c)
  {
    v[c] = w[c];
  }
  vtkMath::Cross(v, n, u);
  vtkMath::Normalize(u);
  return true;
}

bool vtkPenumbraAreaLight::GetCellPosition(int i, int j, double position[3])
{
  const int k = this->SamplesPerAxis;
  double u[3], v[3], n[3];
  if (i < 0 || i >= k || j < 0 || j >= this->GetNumberOfRows() || !this->GetAxes(u, v, n))
  {
    return false;
  }
  double centre[3];
  this->GetCentre(centre);
  this->CellPosition(k, i, j, centre, u, v, position);
  return true;
}

bool vtkPenumbraAreaLight::GetSamplePosition(int index, double position[3])
{
  const int k = this->SamplesPerAxis;
  if (index < 0)
  {
    return false;
  }
  // The sample's cell: rows in order, the kept cells of each.
  for (int j = 0; j < this->GetNumberOfRows(); ++j)
  {
    int first, last;
    if (!this->RowCells(k, j, first, last))
    {
      continue;
    }
    if (index <= last - first)
    {
      return this->GetCellPosition(first + index, j, position);
    }
    index -= last - first + 1;
  }
  return false;
}

bool vtkPenumbraAreaLight::GetSamplePositions(int samplesPerAxis, vtkDoubleArray* positions)
{
  if (!positions)
  {
    return false;
  }
  positions->SetNumberOfComponents(3);
  positions->SetNumberOfTuples(0);
  double u[3], v[3], n[3];
  if (samplesPerAxis < 1 || samplesPerAxis > 256 || !this->GetAxes(u, v, n))
  {
    return false;
  }
  double centre[3];
  this->GetCentre(centre);
  const int k = samplesPerAxis;
  for (int j = 0; j < (this->Shape == Line ? 1 : k); ++j)
  {
    int first, last;
    this->RowCells(k, j, first, last);
    for (int i = first; i <= last; ++i)
    {
      double p[3];
      this->CellPosition(k, i, j, centre, u, v, p);
      positions->InsertNextTuple(p);
    }
  }
  return true;
}

bool vtkPenumbraAreaLight::SetFromLightRadius(vtkLight* light, double radius)
{
  if (!light || !light->GetPositional() || !(radius > 0.0) || !std::isfinite(radius))
  {
    return false;
  }
  this->DeepCopy(light);
  this->SetPositional(true);
  this->SetConeAngle(180.0);
  this->SetShapeToDisc();
  this->SetWidth(2.0 * radius);
  // In-plane orientation does not matter for a disc; the world axis least aligned with the
  // axis keeps the frame well conditioned.
  double n[3];
  for (int c = 0; c < 3; ++c)
  {
    n[c] = std::fabs(light->GetFocalPoint()[c] - light->GetPosition()[c]);
  }
  const int axis = n[0] <= n[1] && n[0] <= n[2] ? 0 : (n[1] <= n[2] ? 1 : 2);
  double up[3] = { 0.0, 0.0, 0.0 };
  up[axis] = 1.0;
  this->SetUp(up);
  return true;
}

bool vtkPenumbraAreaLight::IsRigid()
{
  vtkMatrix4x4* m = this->GetTransformMatrix();
  if (!m)
  {
    return true;
  }
  const double* e = m->GetData();
  if (!(e[12] == 0.0 && e[13] == 0.0 && e[14] == 0.0 && e[15] == 1.0))
  {
    return false; // projective
  }
  // Columns of the 3 x 3 part orthonormal within rounding.
  for (int a = 0; a < 3; ++a)
  {
    for (int b = a; b < 3; ++b)
    {
      double dot = 0.0;
      for (int r = 0; r < 3; ++r)
      {
        dot += e[4 * r + a] * e[4 * r + b];
      }
      if (!(std::fabs(dot - (a == b ? 1.0 : 0.0)) <= 1e-9))
      {
        return false;
      }
    }
  }
  return true;
}

const char* vtkPenumbraAreaLight::GetValidityMessage()
{
  this->ValidityMessage[0] = '\0';
  double u[3], v[3], n[3];
  const bool finite = std::isfinite(this->Width) && std::isfinite(this->Height) &&
    std::isfinite(this->Position[0]) && std::isfinite(this->Position[1]) &&
    std::isfinite(this->Position[2]) && std::isfinite(this->FocalPoint[0]) &&
    std::isfinite(this->FocalPoint[1]) && std::isfinite(this->FocalPoint[2]);
  if (!finite)
  {
    std::snprintf(this->ValidityMessage, sizeof(this->ValidityMessage),
      "position, focal point and size must be finite numbers");
  }
  else if (!(this->Width > 0.0) || (this->Shape == Rectangle && !(this->Height > 0.0)))
  {
    std::snprintf(this->ValidityMessage, sizeof(this->ValidityMessage),
      "size must be positive (got %g x %g); use a point or spot light for a zero-size light",
      this->Width, this->Height);
  }
  else if (!this->IsRigid())
  {
    std::snprintf(this->ValidityMessage, sizeof(this->ValidityMessage),
      "the TransformMatrix must be a rotation and a translation (the size is in world "
      "units, a scaling transform would change it)");
  }
  else if (!this->GetAxes(u, v, n))
  {
    std::snprintf(this->ValidityMessage, sizeof(this->ValidityMessage),
      "position and focal point coincide, so the light has no direction");
  }
  return this->ValidityMessage;
}

vtkLight* vtkPenumbraAreaLight::ShallowClone()
{
  vtkPenumbraAreaLight* clone = vtkPenumbraAreaLight::New();
  clone->DeepCopy(this);
  clone->Shape = this->Shape;
  clone->Width = this->Width;
  clone->Height = this->Height;
  clone->SetUp(this->Up);
  clone->SamplesPerAxis = this->SamplesPerAxis;
  return clone;
}

void vtkPenumbraAreaLight::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Shape: " << this->GetShapeAsString() << "\n";
  os << indent << "Width: " << this->Width << "\n";
  os << indent << "Height: " << this->Height << "\n";
  os << indent << "Up: " << this->Up[0] << " " << this->Up[1] << " " << this->Up[2] << "\n";
  os << indent << "SamplesPerAxis: " << this->SamplesPerAxis << "\n";
}
