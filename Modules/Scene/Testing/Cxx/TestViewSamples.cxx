// View samples: allocation, invalid-by-default samples, row-major bottom-up indexing, the
// check of the arrays every consumer makes, and positions relative to the rebasing origin
// keeping millimetres at city coordinates.
#include "vtkCommand.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkTestErrorObserver.h"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <string>

#include "PenumbraTestMacros.h"

int TestViewSamples(int, char*[])
{
  vtkNew<vtkPenumbraViewSamples> samples;
  CHECK(samples->GetNumberOfSamples() == 0 && samples->GetNumberOfValidSamples() == 0);
  CHECK(samples->CheckArrays().empty()); // 0 x 0 is usable: nothing to read
  CHECK(!samples->IsValid(0));

  samples->SetSize(4, 3);
  CHECK(samples->GetWidth() == 4 && samples->GetHeight() == 3);
  CHECK(samples->GetNumberOfSamples() == 12);
  CHECK(samples->GetPositions()->GetNumberOfTuples() == 12);
  CHECK(samples->GetPositions()->GetNumberOfComponents() == 3);
  CHECK(samples->GetNormals()->GetNumberOfComponents() == 3);
  CHECK(samples->GetPropIndices()->GetNumberOfTuples() == 12);
  CHECK(samples->GetTriangleIds()->GetNumberOfTuples() == 12);
  for (vtkIdType i = 0; i < 12; ++i)
  {
    CHECK(!samples->IsValid(i));
    CHECK(samples->GetPropIndices()->GetValue(i) == -1);
    CHECK(samples->GetTriangleIds()->GetValue(i) == -1);
  }
  CHECK(samples->GetNumberOfValidSamples() == 0);
  CHECK(samples->GetSampleIndex(0, 0) == 0 && samples->GetSampleIndex(3, 0) == 3);
  CHECK(samples->GetSampleIndex(1, 2) == 9 && samples->GetSampleIndex(4, 0) == -1);
  CHECK(samples->GetSampleIndex(0, 3) == -1 && samples->GetSampleIndex(-1, 0) == -1);

  // The arrays as every consumer checks them: usable as SetSize() makes them, and each way a
  // producer can spoil them (the arrays are public) is named.
  CHECK(samples->CheckArrays().empty());
  auto says = [&](const char* text)
  { return samples->CheckArrays().find(text) != std::string::npos; };
  samples->GetPositions()->SetNumberOfTuples(0); // emptied: no positions at all
  CHECK(says("do not match the 4 x 3 size") && says("positions 0, normals 12"));
  samples->SetSize(4, 3);
  samples->GetTriangleIds()->SetNumberOfTuples(13);
  CHECK(says("prop indices 12, triangle ids 13"));
  samples->SetSize(4, 3);
  samples->GetNormals()->SetNumberOfComponents(2);
  CHECK(says("wrong number of components (3, 3, 1, 1 expected)"));
  samples->GetNormals()->SetNumberOfComponents(3);
  samples->GetPropIndices()->SetNumberOfComponents(3);
  CHECK(says("wrong number of components"));
  samples->GetPropIndices()->SetNumberOfComponents(1);
  CHECK(samples->CheckArrays().empty());
  samples->SetOrigin(0.0, std::numeric_limits<double>::quiet_NaN(), 0.0);
  CHECK(samples->CheckArrays() == "view samples have a non-finite origin");
  samples->SetOrigin(0.0, 0.0, std::numeric_limits<double>::infinity());
  CHECK(says("non-finite origin"));
  samples->SetOrigin(0.0, 0.0, 0.0);
  CHECK(samples->CheckArrays().empty());

  // A sample at city coordinates: stored relative to the origin, the millimetre survives.
  samples->SetOrigin(3450000.0, 5430000.0, 0.0);
  samples->SetCameraPosition(3450000.0, 5430000.0, 100.0);
  const double world[3] = { 3450012.345, 5429987.654, 3.001 };
  const double down[3] = { 0, 0, -2 }; // facing away from the camera: gets flipped
  samples->SetSample(samples->GetSampleIndex(1, 2), world, down, 5, 42);
  CHECK(samples->IsValid(9) && samples->GetNumberOfValidSamples() == 1);
  CHECK(samples->GetPropIndices()->GetValue(9) == 5);
  CHECK(samples->GetTriangleIds()->GetValue(9) == 42);
  const float* n = samples->GetNormals()->GetPointer(27);
  CHECK(n[0] == 0.0f && n[1] == 0.0f && n[2] == 1.0f);
  double back[3];
  CHECK(samples->GetWorldPosition(9, back));
  for (int c = 0; c < 3; ++c)
  {
    CHECK(std::fabs(back[c] - world[c]) < 1e-5);
  }
  CHECK(!samples->GetWorldPosition(0, back));

  // Out-of-range writes are refused with an error, not a crash.
  vtkNew<vtkTest::ErrorObserver> observer;
  samples->AddObserver(vtkCommand::ErrorEvent, observer);
  samples->SetSample(12, world, down, 0, 0);
  CHECK(observer->GetError());
  CHECK(samples->GetNumberOfValidSamples() == 1);

  // Resizing invalidates everything; a zero dimension makes an empty buffer.
  samples->SetSize(2, 2);
  CHECK(samples->GetNumberOfSamples() == 4 && samples->GetNumberOfValidSamples() == 0);
  samples->SetSize(5, 0);
  CHECK(samples->GetWidth() == 0 && samples->GetNumberOfSamples() == 0);
  return EXIT_SUCCESS;
}
