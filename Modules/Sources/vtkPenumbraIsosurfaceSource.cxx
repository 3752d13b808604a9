#include "vtkPenumbraIsosurfaceSource.h"

#include "vtkContourFilter.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraSourcesPrivate.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStructuredPointsReader.h"
#include "vtkXMLImageDataReader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <string>
#include <system_error>

namespace
{
constexpr int MaxResolution = 1024;

struct Blob
{
  double Center[3];
  double Sigma;
};

// Placed so that, at iso 0.5, the components stay apart (each blob's surface is ~1.18 sigma
// from its centre) and clear of the [-1, 1]^3 border, so every component is closed. D1 and D2
// overlap on purpose and merge into one two-lobed body.
const Blob Blobs[] = {
  { { 0.0, 0.0, 0.35 }, 0.22 },    // A: over the torus hole
  { { 0.55, 0.5, 0.5 }, 0.15 },    // B
  { { -0.5, -0.45, 0.45 }, 0.17 }, // C
  { { 0.0, -0.1, -0.6 }, 0.14 },   // D1
  { { 0.25, 0.1, -0.65 }, 0.14 },  // D2
};
constexpr double TorusRadius = 0.55;
constexpr double TorusHeight = -0.15;
constexpr double TorusSigma = 0.12;

// Field on normalized coordinates in [-1, 1]^3, peaks ~1.
double ProceduralField(double x, double y, double z)
{
  double f = 0.0;
  for (const Blob& b : Blobs)
  {
    const double dx = x - b.Center[0], dy = y - b.Center[1], dz = z - b.Center[2];
    f += std::exp(-(dx * dx + dy * dy + dz * dz) / (2.0 * b.Sigma * b.Sigma));
  }
  const double radial = std::sqrt(x * x + y * y) - TorusRadius;
  const double dz = z - TorusHeight;
  f += std::exp(-(radial * radial + dz * dz) / (2.0 * TorusSigma * TorusSigma));
  return f;
}

std::string LowerCaseExtension(const std::string& fileName)
{
  std::string ext = std::filesystem::path(fileName).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
    [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return ext;
}
}

vtkStandardNewMacro(vtkPenumbraIsosurfaceSource);

vtkPenumbraIsosurfaceSource::vtkPenumbraIsosurfaceSource()
  : FileName(nullptr)
  , IsoValue(0.5)
  , Resolution(48)
  , Bounds{ -1.0, 1.0, -1.0, 1.0, -1.0, 1.0 }
{
  this->SetNumberOfInputPorts(0);
}

vtkPenumbraIsosurfaceSource::~vtkPenumbraIsosurfaceSource()
{
  this->SetFileName(nullptr);
}

bool vtkPenumbraIsosurfaceSource::MakeProceduralVolume(vtkImageData* volume)
{
  if (this->Resolution < 2 || this->Resolution > MaxResolution)
  {
    vtkErrorMacro(
      "Resolution must be in [2, " << MaxResolution << "] samples, got " << this->Resolution);
    return false;
  }
  for (int axis = 0; axis < 3; ++axis)
  {
    const double lo = this->Bounds[2 * axis], hi = this->Bounds[2 * axis + 1];
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi))
    {
      vtkErrorMacro("Bounds must be finite with min < max on every axis, got axis "
        << axis << " = [" << lo << ", " << hi << "]");
      return false;
    }
  }

  const int n = this->Resolution;
  volume->SetDimensions(n, n, n);
  volume->SetOrigin(this->Bounds[0], this->Bounds[2], this->Bounds[4]);
  volume->SetSpacing((this->Bounds[1] - this->Bounds[0]) / (n - 1),
    (this->Bounds[3] - this->Bounds[2]) / (n - 1), (this->Bounds[5] - this->Bounds[4]) / (n - 1));

  vtkNew<vtkFloatArray> field;
  field->SetName("ProceduralField");
  field->SetNumberOfTuples(static_cast<vtkIdType>(n) * n * n);
  float* out = field->GetPointer(0);
  const double step = 2.0 / (n - 1);
  vtkIdType id = 0;
  for (int k = 0; k < n; ++k)
  {
    for (int j = 0; j < n; ++j)
    {
      for (int i = 0; i < n; ++i)
      {
        out[id++] =
          static_cast<float>(ProceduralField(-1.0 + i * step, -1.0 + j * step, -1.0 + k * step));
      }
    }
  }
  volume->GetPointData()->SetScalars(field);
  return true;
}

bool vtkPenumbraIsosurfaceSource::ReadVolume(vtkImageData* volume)
{
  const std::string fileName = this->FileName;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(fileName, ec))
  {
    vtkErrorMacro("Volume file \"" << fileName << "\" does not exist or is not a file");
    return false;
  }

  vtkNew<penumbra_sources::MessageCollector> messages;
  vtkSmartPointer<vtkAlgorithm> reader;
  const std::string ext = LowerCaseExtension(fileName);
  if (ext == ".vtk")
  {
    auto legacy = vtkSmartPointer<vtkStructuredPointsReader>::New();
    legacy->SetFileName(fileName.c_str());
    reader = legacy;
  }
  else if (ext == ".vti")
  {
    auto xml = vtkSmartPointer<vtkXMLImageDataReader>::New();
    xml->SetFileName(fileName.c_str());
    // The XML parser is a separate object that would otherwise print its own errors.
    xml->SetReaderErrorObserver(messages);
    xml->SetParserErrorObserver(messages);
    reader = xml;
  }
  else
  {
    vtkErrorMacro("Unsupported volume file \"" << fileName
                                               << "\": expected a .vtk (structured points) or "
                                                  ".vti file");
    return false;
  }

  messages->Watch(reader);
  reader->Update();
  if (messages->HasError())
  {
    vtkErrorMacro("Reading \"" << fileName << "\" failed: " << messages->GetErrors());
    return false;
  }
  if (!messages->GetWarnings().empty())
  {
    vtkWarningMacro("While reading \"" << fileName << "\": " << messages->GetWarnings());
  }

  vtkImageData* image = vtkImageData::SafeDownCast(reader->GetOutputDataObject(0));
  int dims[3] = { 0, 0, 0 };
  if (image)
  {
    image->GetDimensions(dims);
  }
  if (!image || dims[0] < 2 || dims[1] < 2 || dims[2] < 2)
  {
    vtkErrorMacro("\"" << fileName << "\" is not a 3-D volume (dimensions " << dims[0] << " x "
                       << dims[1] << " x " << dims[2] << ")");
    return false;
  }
  if (!image->GetPointData()->GetScalars())
  {
    vtkErrorMacro("\"" << fileName << "\" has no active point scalars to contour");
    return false;
  }
  volume->ShallowCopy(image);
  return true;
}

int vtkPenumbraIsosurfaceSource::RequestData(vtkInformation* vtkNotUsed(request),
  vtkInformationVector** vtkNotUsed(inputVector), vtkInformationVector* outputVector)
{
  vtkPolyData* output = vtkPolyData::GetData(outputVector);
  output->Initialize();

  if (!std::isfinite(this->IsoValue))
  {
    vtkErrorMacro("IsoValue must be finite, got " << this->IsoValue);
    return 0;
  }

  vtkNew<vtkImageData> volume;
  const bool fromFile = this->FileName && this->FileName[0] != '\0';
  if (!(fromFile ? this->ReadVolume(volume) : this->MakeProceduralVolume(volume)))
  {
    return 0;
  }

  // vtkContourFilter (synchronized templates for images) rather than vtkFlyingEdges3D:
  // flying edges emits zero-area triangles wherever a sample equals IsoValue exactly, which
  // is common with integer-valued volumes (about 4% extra triangles on carotid.vtk at 90).
  vtkNew<vtkContourFilter> contour;
  contour->SetInputData(volume);
  contour->SetValue(0, this->IsoValue);
  contour->ComputeNormalsOn();
  contour->ComputeGradientsOff();
  contour->GenerateTrianglesOn();
  // A scalar array equal to IsoValue everywhere would only make mappers colour by it.
  contour->ComputeScalarsOff();
  vtkNew<penumbra_sources::MessageCollector> messages;
  messages->Watch(contour);
  contour->Update();
  if (messages->HasError())
  {
    vtkErrorMacro("Contouring failed: " << messages->GetErrors());
    return 0;
  }

  output->ShallowCopy(contour->GetOutput());
  return 1;
}

void vtkPenumbraIsosurfaceSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "IsoValue: " << this->IsoValue << "\n";
  os << indent << "Resolution: " << this->Resolution << "\n";
  os << indent << "Bounds: (" << this->Bounds[0] << ", " << this->Bounds[1] << ", "
     << this->Bounds[2] << ", " << this->Bounds[3] << ", " << this->Bounds[4] << ", "
     << this->Bounds[5] << ")\n";
}
