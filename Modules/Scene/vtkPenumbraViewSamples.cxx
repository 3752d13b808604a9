#include "vtkPenumbraViewSamples.h"

#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"

#include <algorithm>
#include <cmath>
#include <sstream>

vtkStandardNewMacro(vtkPenumbraViewSamples);

struct vtkPenumbraViewSamples::Internals
{
  int Width = 0;
  int Height = 0;
  vtkNew<vtkFloatArray> Positions;
  vtkNew<vtkFloatArray> Normals;
  vtkNew<vtkIntArray> PropIndices;
  vtkNew<vtkIdTypeArray> TriangleIds;
};

//------------------------------------------------------------------------------
vtkPenumbraViewSamples::vtkPenumbraViewSamples()
  : Impl(new Internals)
{
  this->Origin[0] = this->Origin[1] = this->Origin[2] = 0.0;
  this->CameraPosition[0] = this->CameraPosition[1] = this->CameraPosition[2] = 0.0;
  this->Impl->Positions->SetName("Positions");
  this->Impl->Positions->SetNumberOfComponents(3);
  this->Impl->Normals->SetName("Normals");
  this->Impl->Normals->SetNumberOfComponents(3);
  this->Impl->PropIndices->SetName("PropIndices");
  this->Impl->TriangleIds->SetName("TriangleIds");
}

//------------------------------------------------------------------------------
vtkPenumbraViewSamples::~vtkPenumbraViewSamples() = default;

//------------------------------------------------------------------------------
void vtkPenumbraViewSamples::SetSize(int width, int height)
{
  width = width < 0 ? 0 : width;
  height = height < 0 ? 0 : height;
  // A zero dimension makes an empty buffer; keep the other at 0 too so Width*Height agrees.
  if (width == 0 || height == 0)
  {
    width = height = 0;
  }
  Internals& impl = *this->Impl;
  impl.Width = width;
  impl.Height = height;
  const vtkIdType n = static_cast<vtkIdType>(width) * height;
  impl.Positions->SetNumberOfTuples(n);
  impl.Normals->SetNumberOfTuples(n);
  impl.PropIndices->SetNumberOfTuples(n);
  impl.TriangleIds->SetNumberOfTuples(n);
  impl.Positions->FillValue(0.0f);
  impl.Normals->FillValue(0.0f);
  impl.PropIndices->FillValue(-1);
  impl.TriangleIds->FillValue(-1);
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkPenumbraViewSamples::DeepCopy(vtkPenumbraViewSamples* other)
{
  if (!other || other == this)
  {
    return;
  }
  Internals& impl = *this->Impl;
  const Internals& src = *other->Impl;
  impl.Width = src.Width;
  impl.Height = src.Height;
  impl.Positions->DeepCopy(src.Positions);
  impl.Normals->DeepCopy(src.Normals);
  impl.PropIndices->DeepCopy(src.PropIndices);
  impl.TriangleIds->DeepCopy(src.TriangleIds);
  this->SetOrigin(other->GetOrigin());
  this->SetCameraPosition(other->GetCameraPosition());
  this->Modified();
}

//------------------------------------------------------------------------------
int vtkPenumbraViewSamples::GetWidth()
{
  return this->Impl->Width;
}

//------------------------------------------------------------------------------
int vtkPenumbraViewSamples::GetHeight()
{
  return this->Impl->Height;
}

//------------------------------------------------------------------------------
vtkIdType vtkPenumbraViewSamples::GetNumberOfSamples()
{
  return static_cast<vtkIdType>(this->Impl->Width) * this->Impl->Height;
}

//------------------------------------------------------------------------------
vtkFloatArray* vtkPenumbraViewSamples::GetPositions()
{
  return this->Impl->Positions;
}

//------------------------------------------------------------------------------
vtkFloatArray* vtkPenumbraViewSamples::GetNormals()
{
  return this->Impl->Normals;
}

//------------------------------------------------------------------------------
vtkIntArray* vtkPenumbraViewSamples::GetPropIndices()
{
  return this->Impl->PropIndices;
}

//------------------------------------------------------------------------------
vtkIdTypeArray* vtkPenumbraViewSamples::GetTriangleIds()
{
  return this->Impl->TriangleIds;
}

//------------------------------------------------------------------------------
std::string vtkPenumbraViewSamples::CheckArrays()
{
  // The arrays are made by the constructor and never replaced, so none is null.
  const Internals& impl = *this->Impl;
  const vtkIdType n = this->GetNumberOfSamples();
  if (impl.Positions->GetNumberOfComponents() != 3 || impl.Normals->GetNumberOfComponents() != 3 ||
    impl.PropIndices->GetNumberOfComponents() != 1 ||
    impl.TriangleIds->GetNumberOfComponents() != 1)
  {
    return "view sample arrays have the wrong number of components (3, 3, 1, 1 expected)";
  }
  if (impl.Positions->GetNumberOfTuples() != n || impl.Normals->GetNumberOfTuples() != n ||
    impl.PropIndices->GetNumberOfTuples() != n || impl.TriangleIds->GetNumberOfTuples() != n)
  {
    std::ostringstream msg;
    msg << "view sample arrays do not match the " << impl.Width << " x " << impl.Height
        << " size: positions " << impl.Positions->GetNumberOfTuples() << ", normals "
        << impl.Normals->GetNumberOfTuples() << ", prop indices "
        << impl.PropIndices->GetNumberOfTuples() << ", triangle ids "
        << impl.TriangleIds->GetNumberOfTuples();
    return msg.str();
  }
  if (!std::isfinite(this->Origin[0]) || !std::isfinite(this->Origin[1]) ||
    !std::isfinite(this->Origin[2]))
  {
    return "view samples have a non-finite origin";
  }
  return std::string();
}

//------------------------------------------------------------------------------
bool vtkPenumbraViewSamples::IsValid(vtkIdType sample)
{
  // The arrays are public, so a producer may have resized them: check against their length.
  vtkIntArray* props = this->Impl->PropIndices;
  return sample >= 0 && sample < this->GetNumberOfSamples() &&
    sample < props->GetNumberOfTuples() && props->GetValue(sample) >= 0;
}

//------------------------------------------------------------------------------
vtkIdType vtkPenumbraViewSamples::GetNumberOfValidSamples()
{
  vtkIntArray* props = this->Impl->PropIndices;
  const vtkIdType n = std::min(this->GetNumberOfSamples(), props->GetNumberOfTuples());
  vtkIdType valid = 0;
  for (vtkIdType i = 0; i < n; ++i)
  {
    valid += props->GetValue(i) >= 0 ? 1 : 0;
  }
  return valid;
}

//------------------------------------------------------------------------------
vtkIdType vtkPenumbraViewSamples::GetSampleIndex(int x, int y)
{
  if (x < 0 || y < 0 || x >= this->Impl->Width || y >= this->Impl->Height)
  {
    return -1;
  }
  return static_cast<vtkIdType>(y) * this->Impl->Width + x;
}

//------------------------------------------------------------------------------
bool vtkPenumbraViewSamples::GetWorldPosition(vtkIdType sample, double world[3])
{
  if (!this->IsValid(sample) || sample >= this->Impl->Positions->GetNumberOfTuples())
  {
    return false;
  }
  const float* p = this->Impl->Positions->GetPointer(3 * sample);
  for (int c = 0; c < 3; ++c)
  {
    world[c] = static_cast<double>(p[c]) + this->Origin[c];
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkPenumbraViewSamples::SetSample(vtkIdType sample, const double world[3],
  const double normal[3], int propIndex, vtkIdType triangleId)
{
  Internals& impl = *this->Impl;
  if (sample < 0 || sample >= this->GetNumberOfSamples() ||
    sample >= impl.Positions->GetNumberOfTuples() || sample >= impl.Normals->GetNumberOfTuples() ||
    sample >= impl.PropIndices->GetNumberOfTuples() ||
    sample >= impl.TriangleIds->GetNumberOfTuples())
  {
    vtkErrorMacro(
      "SetSample: sample " << sample << " out of range [0, " << this->GetNumberOfSamples() << ")");
    return;
  }
  double rel[3], n[3] = { normal[0], normal[1], normal[2] }, toCamera[3];
  for (int c = 0; c < 3; ++c)
  {
    // Subtract in double first: that is what keeps millimetres at city coordinates.
    rel[c] = world[c] - this->Origin[c];
    toCamera[c] = this->CameraPosition[c] - world[c];
  }
  if (vtkMath::Normalize(n) > 0.0 && vtkMath::Dot(n, toCamera) < 0.0)
  {
    n[0] = -n[0];
    n[1] = -n[1];
    n[2] = -n[2];
  }
  float* p = impl.Positions->GetPointer(3 * sample);
  float* q = impl.Normals->GetPointer(3 * sample);
  for (int c = 0; c < 3; ++c)
  {
    p[c] = static_cast<float>(rel[c]);
    q[c] = static_cast<float>(n[c]);
  }
  impl.PropIndices->SetValue(sample, propIndex);
  impl.TriangleIds->SetValue(sample, triangleId);
  impl.Positions->Modified();
  impl.Normals->Modified();
  impl.PropIndices->Modified();
  impl.TriangleIds->Modified();
}

//------------------------------------------------------------------------------
void vtkPenumbraViewSamples::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Size: " << this->Impl->Width << " x " << this->Impl->Height << "\n";
  os << indent << "Origin: (" << this->Origin[0] << ", " << this->Origin[1] << ", "
     << this->Origin[2] << ")\n";
  os << indent << "CameraPosition: (" << this->CameraPosition[0] << ", " << this->CameraPosition[1]
     << ", " << this->CameraPosition[2] << ")\n";
  os << indent << "NumberOfValidSamples: " << this->GetNumberOfValidSamples() << "\n";
}
