#include "vtkPenumbraTerrainSource.h"

#include "vtkCellArray.h"
#include "vtkDEMReader.h"
#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraSourcesPrivate.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace
{
// Indices 0, rate, 2*rate, ... and always the last one, so subsampling never crops the DEM.
std::vector<int> SampleIndices(int count, int rate)
{
  std::vector<int> indices;
  for (long long i = 0; i < count; i += rate)
  {
    indices.push_back(static_cast<int>(i));
  }
  if (indices.back() != count - 1)
  {
    indices.push_back(count - 1);
  }
  return indices;
}
}

vtkStandardNewMacro(vtkPenumbraTerrainSource);

vtkPenumbraTerrainSource::vtkPenumbraTerrainSource()
  : FileName(nullptr)
  , VerticalScale(1.0)
  , SampleRate(1)
{
  this->SetNumberOfInputPorts(0);
}

vtkPenumbraTerrainSource::~vtkPenumbraTerrainSource()
{
  this->SetFileName(nullptr);
}

int vtkPenumbraTerrainSource::RequestData(vtkInformation* vtkNotUsed(request),
  vtkInformationVector** vtkNotUsed(inputVector), vtkInformationVector* outputVector)
{
  vtkPolyData* output = vtkPolyData::GetData(outputVector);
  output->Initialize();

  if (!std::isfinite(this->VerticalScale) || this->VerticalScale <= 0.0)
  {
    vtkErrorMacro("VerticalScale must be finite and > 0, got " << this->VerticalScale);
    return 0;
  }
  if (this->SampleRate < 1)
  {
    vtkErrorMacro("SampleRate must be >= 1, got " << this->SampleRate);
    return 0;
  }
  if (!this->FileName || this->FileName[0] == '\0')
  {
    vtkErrorMacro("No FileName: set it to a USGS DEM file");
    return 0;
  }
  const std::string fileName = this->FileName;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(fileName, ec))
  {
    vtkErrorMacro("DEM file \"" << fileName << "\" does not exist or is not a file");
    return 0;
  }

  vtkNew<vtkDEMReader> reader;
  reader->SetFileName(fileName.c_str());
  reader->SetElevationReferenceToSeaLevel();
  vtkNew<penumbra_sources::MessageCollector> messages;
  messages->Watch(reader);
  reader->Update();
  if (messages->HasError())
  {
    vtkErrorMacro("Reading DEM \"" << fileName << "\" failed: " << messages->GetErrors());
    return 0;
  }
  if (!messages->GetWarnings().empty())
  {
    vtkWarningMacro("While reading DEM \"" << fileName << "\": " << messages->GetWarnings());
  }

  vtkImageData* image = reader->GetOutput();
  int dims[3];
  image->GetDimensions(dims);
  vtkDataArray* elevation = image->GetPointData()->GetScalars();
  if (dims[0] < 2 || dims[1] < 2 || !elevation ||
    elevation->GetNumberOfTuples() < static_cast<vtkIdType>(dims[0]) * dims[1])
  {
    vtkErrorMacro("\"" << fileName << "\" holds no usable elevation grid (dimensions " << dims[0]
                       << " x " << dims[1] << ")");
    return 0;
  }
  double origin[3], spacing[3];
  image->GetOrigin(origin);
  image->GetSpacing(spacing);

  const std::vector<int> xi = SampleIndices(dims[0], this->SampleRate);
  const std::vector<int> yi = SampleIndices(dims[1], this->SampleRate);
  const int nx = static_cast<int>(xi.size());
  const int ny = static_cast<int>(yi.size());

  std::vector<double> xs(nx), ys(ny), zs(static_cast<size_t>(nx) * ny);
  for (int a = 0; a < nx; ++a)
  {
    xs[a] = origin[0] + xi[a] * spacing[0];
  }
  for (int b = 0; b < ny; ++b)
  {
    ys[b] = origin[1] + yi[b] * spacing[1];
  }
  for (int b = 0; b < ny; ++b)
  {
    for (int a = 0; a < nx; ++a)
    {
      const vtkIdType src = static_cast<vtkIdType>(yi[b]) * dims[0] + xi[a];
      zs[static_cast<size_t>(b) * nx + a] = this->VerticalScale * elevation->GetComponent(src, 0);
    }
  }
  auto z = [&](int a, int b) { return zs[static_cast<size_t>(b) * nx + a]; };

  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(nx) * ny);
  vtkNew<vtkFloatArray> normals;
  normals->SetName("Normals");
  normals->SetNumberOfComponents(3);
  normals->SetNumberOfTuples(static_cast<vtkIdType>(nx) * ny);
  for (int b = 0; b < ny; ++b)
  {
    const int b0 = std::max(b - 1, 0), b1 = std::min(b + 1, ny - 1);
    for (int a = 0; a < nx; ++a)
    {
      const int a0 = std::max(a - 1, 0), a1 = std::min(a + 1, nx - 1);
      const vtkIdType id = static_cast<vtkIdType>(b) * nx + a;
      points->SetPoint(id, xs[a], ys[b], z(a, b));
      const double dzdx = (z(a1, b) - z(a0, b)) / (xs[a1] - xs[a0]);
      const double dzdy = (z(a, b1) - z(a, b0)) / (ys[b1] - ys[b0]);
      const double len = std::sqrt(dzdx * dzdx + dzdy * dzdy + 1.0);
      normals->SetTypedTuple(id,
        std::array<float, 3>{ static_cast<float>(-dzdx / len), static_cast<float>(-dzdy / len),
          static_cast<float>(1.0 / len) }
          .data());
    }
  }

  // Counter-clockwise from above for positive spacings; a mirrored grid needs the other
  // winding to keep triangle normals up.
  const bool flip = spacing[0] * spacing[1] < 0.0;
  vtkNew<vtkCellArray> polys;
  polys->AllocateExact(
    2 * static_cast<vtkIdType>(nx - 1) * (ny - 1), 6 * static_cast<vtkIdType>(nx - 1) * (ny - 1));
  for (int b = 0; b + 1 < ny; ++b)
  {
    for (int a = 0; a + 1 < nx; ++a)
    {
      const vtkIdType p00 = static_cast<vtkIdType>(b) * nx + a;
      const vtkIdType p10 = p00 + 1, p01 = p00 + nx, p11 = p01 + 1;
      const vtkIdType t0[3] = { p00, flip ? p11 : p10, flip ? p10 : p11 };
      const vtkIdType t1[3] = { p00, flip ? p01 : p11, flip ? p11 : p01 };
      polys->InsertNextCell(3, t0);
      polys->InsertNextCell(3, t1);
    }
  }

  output->SetPoints(points);
  output->SetPolys(polys);
  output->GetPointData()->SetNormals(normals);
  return 1;
}

void vtkPenumbraTerrainSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "VerticalScale: " << this->VerticalScale << "\n";
  os << indent << "SampleRate: " << this->SampleRate << "\n";
}
