#include "vtkPenumbraMetrics.h"

#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraImageIO.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkPenumbraMetrics);

namespace
{
// Per-sample classes of a hard comparison, for the error image.
enum SampleClass : unsigned char
{
  ClassBackground = 0,
  ClassAgreeShadow,
  ClassAgreeLit,
  ClassFalseLit,
  ClassFalseShadow,
  ClassTie,
  ClassExcluded
};

enum class Kind
{
  None,
  Hard,
  Soft
};

bool SameSize(vtkUnsignedCharArray* a, vtkIdType n);

// Why the arrays of a comparison cannot be compared, or nullptr if they can.
const char* InputProblem(vtkFloatArray* test, vtkFloatArray* reference, vtkUnsignedCharArray* ties,
  vtkUnsignedCharArray* mask)
{
  if (!test || !reference)
  {
    return "the test and reference arrays are required";
  }
  const vtkIdType n = reference->GetNumberOfTuples();
  if (test->GetNumberOfComponents() != 1 || reference->GetNumberOfComponents() != 1 ||
    test->GetNumberOfTuples() != n || !SameSize(ties, n) || !SameSize(mask, n))
  {
    return "test, reference, ties and mask arrays must have one component and the same "
           "number of tuples";
  }
  return nullptr;
}

bool SameSize(vtkUnsignedCharArray* a, vtkIdType n)
{
  return !a || (a->GetNumberOfComponents() == 1 && a->GetNumberOfTuples() == n);
}
}

struct vtkPenumbraMetrics::Internals
{
  Kind Last = Kind::None;
  std::vector<unsigned char> Classes; // hard: SampleClass per sample
  std::vector<float> Errors;          // soft: |error| per sample, -1 where not compared
  std::string Error;
};

//------------------------------------------------------------------------------
vtkPenumbraMetrics::vtkPenumbraMetrics()
  : LitThreshold(0.5)
  , Impl(new Internals)
{
  this->Reset();
}

//------------------------------------------------------------------------------
vtkPenumbraMetrics::~vtkPenumbraMetrics() = default;

//------------------------------------------------------------------------------
void vtkPenumbraMetrics::Reset()
{
  this->Candidates = 0;
  this->Ties = 0;
  this->Missing = 0;
  this->FalseLit = 0;
  this->FalseShadow = 0;
  this->MismatchRate = 0.0;
  this->MAE = 0.0;
  this->RMSE = 0.0;
  this->MaxError = 0.0;
  this->P95Error = 0.0;
  this->Impl->Last = Kind::None;
  this->Impl->Classes.clear();
  this->Impl->Errors.clear();
  this->Impl->Error.clear();
}

//------------------------------------------------------------------------------
int vtkPenumbraMetrics::Fail(const char* message)
{
  this->Impl->Error = message;
  vtkErrorMacro(<< message);
  return 0;
}

//------------------------------------------------------------------------------
const char* vtkPenumbraMetrics::GetErrorMessage()
{
  return this->Impl->Error.c_str();
}

//------------------------------------------------------------------------------
int vtkPenumbraMetrics::CompareHard(vtkFloatArray* test, vtkFloatArray* reference,
  vtkUnsignedCharArray* ties, vtkUnsignedCharArray* candidates)
{
  this->Reset();
  if (const char* why = InputProblem(test, reference, ties, candidates))
  {
    return this->Fail((std::string("CompareHard: ") + why).c_str());
  }
  const vtkIdType n = reference->GetNumberOfTuples();
  Internals& impl = *this->Impl;
  impl.Classes.assign(static_cast<size_t>(n), ClassBackground);
  const double threshold = this->LitThreshold;
  for (vtkIdType i = 0; i < n; ++i)
  {
    const float ref = reference->GetValue(i);
    if (!(ref >= 0.0f))
    {
      continue;
    }
    if (candidates && !candidates->GetValue(i))
    {
      impl.Classes[i] = ClassExcluded;
      continue;
    }
    if (ties && ties->GetValue(i))
    {
      impl.Classes[i] = ClassTie;
      ++this->Ties;
      continue;
    }
    const float value = test->GetValue(i);
    ++this->Candidates;
    if (!(value >= 0.0f))
    {
      ++this->Missing;
    }
    const bool testLit = value >= threshold;
    const bool refLit = ref >= threshold;
    if (testLit && !refLit)
    {
      impl.Classes[i] = ClassFalseLit;
      ++this->FalseLit;
    }
    else if (!testLit && refLit)
    {
      impl.Classes[i] = ClassFalseShadow;
      ++this->FalseShadow;
    }
    else
    {
      impl.Classes[i] = refLit ? ClassAgreeLit : ClassAgreeShadow;
    }
  }
  this->MismatchRate = this->Candidates ? static_cast<double>(this->FalseLit + this->FalseShadow) /
      static_cast<double>(this->Candidates)
                                        : 0.0;
  impl.Last = Kind::Hard;
  this->Modified();
  return 1;
}

//------------------------------------------------------------------------------
int vtkPenumbraMetrics::CompareSoft(vtkFloatArray* test, vtkFloatArray* reference,
  vtkUnsignedCharArray* mask, vtkUnsignedCharArray* ties)
{
  this->Reset();
  if (const char* why = InputProblem(test, reference, ties, mask))
  {
    return this->Fail((std::string("CompareSoft: ") + why).c_str());
  }
  const vtkIdType n = reference->GetNumberOfTuples();
  Internals& impl = *this->Impl;
  impl.Errors.assign(static_cast<size_t>(n), -1.0f);
  std::vector<double> errors;
  errors.reserve(static_cast<size_t>(n));
  double sum = 0.0;
  double sumSquares = 0.0;
  for (vtkIdType i = 0; i < n; ++i)
  {
    const float ref = reference->GetValue(i);
    if (!(ref >= 0.0f) || (mask && !mask->GetValue(i)))
    {
      continue;
    }
    if (ties && ties->GetValue(i))
    {
      ++this->Ties;
      continue;
    }
    const float value = test->GetValue(i);
    if (!(value >= 0.0f))
    {
      ++this->Missing;
    }
    const double e = std::fabs(static_cast<double>(value) - static_cast<double>(ref));
    impl.Errors[i] = static_cast<float>(e);
    errors.push_back(e);
    sum += e;
    sumSquares += e * e;
    this->MaxError = std::max(this->MaxError, e);
  }
  const size_t count = errors.size();
  this->Candidates = static_cast<vtkIdType>(count);
  if (count > 0)
  {
    this->MAE = sum / static_cast<double>(count);
    this->RMSE = std::sqrt(sumSquares / static_cast<double>(count));
    // Nearest rank: the ceil(0.95 N)-th smallest value (1-based).
    const size_t rank = static_cast<size_t>(std::ceil(0.95 * static_cast<double>(count)));
    const size_t index = std::min(count, std::max<size_t>(rank, 1)) - 1;
    std::nth_element(
      errors.begin(), errors.begin() + static_cast<std::ptrdiff_t>(index), errors.end());
    this->P95Error = errors[index];
  }
  impl.Last = Kind::Soft;
  this->Modified();
  return 1;
}

//------------------------------------------------------------------------------
int vtkPenumbraMetrics::WriteErrorImage(int width, int height, const char* path)
{
  Internals& impl = *this->Impl;
  impl.Error.clear();
  if (impl.Last == Kind::None)
  {
    return this->Fail("WriteErrorImage: no successful comparison to draw");
  }
  const size_t n = impl.Last == Kind::Hard ? impl.Classes.size() : impl.Errors.size();
  if (width < 1 || height < 1 || static_cast<size_t>(width) * static_cast<size_t>(height) != n)
  {
    return this->Fail(
      ("WriteErrorImage: " + std::to_string(width) + " x " + std::to_string(height) +
        " does not match the " + std::to_string(n) + " samples of the last comparison")
        .c_str());
  }
  vtkNew<vtkImageData> image;
  image->SetDimensions(width, height, 1);
  image->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto* rgb = static_cast<unsigned char*>(image->GetScalarPointer());
  auto put = [rgb](size_t i, unsigned char r, unsigned char g, unsigned char b)
  {
    rgb[3 * i] = r;
    rgb[3 * i + 1] = g;
    rgb[3 * i + 2] = b;
  };
  if (impl.Last == Kind::Hard)
  {
    for (size_t i = 0; i < n; ++i)
    {
      switch (impl.Classes[i])
      {
        case ClassAgreeShadow:
          put(i, 0, 0, 0);
          break;
        case ClassAgreeLit:
          put(i, 255, 255, 255);
          break;
        case ClassFalseLit:
          put(i, 255, 0, 0);
          break;
        case ClassFalseShadow:
          put(i, 0, 0, 255);
          break;
        case ClassTie:
          put(i, 255, 255, 0);
          break;
        case ClassExcluded:
          put(i, 128, 128, 128);
          break;
        default:
          put(i, 64, 64, 64);
          break;
      }
    }
  }
  else
  {
    const double maximum = this->MaxError;
    for (size_t i = 0; i < n; ++i)
    {
      const float e = impl.Errors[i];
      if (e < 0.0f)
      {
        put(i, 40, 40, 56);
        continue;
      }
      const double level = maximum > 0.0 ? std::min(1.0, e / maximum) : 0.0;
      const auto grey = static_cast<unsigned char>(std::lround(255.0 * level));
      put(i, grey, grey, grey);
    }
  }
  vtkNew<vtkPenumbraImageIO> io;
  if (!io->Write(image, path))
  {
    return this->Fail(("WriteErrorImage: " + std::string(io->GetErrorMessage())).c_str());
  }
  return 1;
}

//------------------------------------------------------------------------------
void vtkPenumbraMetrics::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "LitThreshold: " << this->LitThreshold << "\n";
  os << indent << "Candidates: " << this->Candidates << "\n";
  os << indent << "Ties: " << this->Ties << "\n";
  os << indent << "Missing: " << this->Missing << "\n";
  os << indent << "FalseLit: " << this->FalseLit << "\n";
  os << indent << "FalseShadow: " << this->FalseShadow << "\n";
  os << indent << "MismatchRate: " << this->MismatchRate << "\n";
  os << indent << "MAE: " << this->MAE << "\n";
  os << indent << "RMSE: " << this->RMSE << "\n";
  os << indent << "MaxError: " << this->MaxError << "\n";
  os << indent << "P95Error: " << this->P95Error << "\n";
}
