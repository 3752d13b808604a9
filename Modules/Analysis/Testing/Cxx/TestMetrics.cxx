// Error metrics on hand-made buffers with figures worked out by hand: hard mismatch counts
// (threshold, ties, candidate mask, background, lost samples), soft MAE / RMSE / max / 95th
// percentile, the colours of the error images, and bad input.
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPenumbraImageIO.h"
#include "vtkPenumbraMetrics.h"
#include "vtkTestUtilities.h"
#include "vtkUnsignedCharArray.h"

#include <cmath>
#include <cstdlib>
#include <initializer_list>
#include <iostream>
#include <string>

#include "PenumbraReferenceScenes.h"
#include "PenumbraTestMacros.h"

namespace
{
void Fill(vtkFloatArray* a, std::initializer_list<float> values)
{
  a->SetNumberOfTuples(static_cast<vtkIdType>(values.size()));
  vtkIdType i = 0;
  for (float v : values)
  {
    a->SetValue(i++, v);
  }
}

void Fill(vtkUnsignedCharArray* a, std::initializer_list<int> values)
{
  a->SetNumberOfTuples(static_cast<vtkIdType>(values.size()));
  vtkIdType i = 0;
  for (int v : values)
  {
    a->SetValue(i++, static_cast<unsigned char>(v));
  }
}

bool Near(double a, double b)
{
  return std::fabs(a - b) < 1e-6;
}

bool Pixel(vtkImageData* image, int x, int y, int r, int g, int b)
{
  auto* p = static_cast<unsigned char*>(image->GetScalarPointer(x, y, 0));
  return p[0] == r && p[1] == g && p[2] == b;
}

int Hard(const std::string& dir)
{
  vtkNew<vtkPenumbraMetrics> metrics;
  vtkNew<vtkFloatArray> test, reference;
  vtkNew<vtkUnsignedCharArray> ties, candidates;
  // sample:        0  1  2  3  4     5     6     7  8   9
  // class:        lit sh FL FS lit   sh    FL  tie  FS  bg
  Fill(test, { 1, 0, 1, 0, 0.6f, 0.4f, 0.5f, 0, -1, 1 });
  Fill(reference, { 1, 0, 0, 1, 1, 0, 0, 1, 1, -1 });
  Fill(ties, { 0, 0, 0, 0, 0, 0, 0, 1, 0, 0 });
  CHECK(metrics->CompareHard(test, reference, ties));
  CHECK(metrics->GetCandidates() == 8);
  CHECK(metrics->GetTies() == 1);
  CHECK(metrics->GetFalseLit() == 2);    // 2, and 6 (0.5 counts as lit)
  CHECK(metrics->GetFalseShadow() == 2); // 3, and 8 (lost sample, -1)
  CHECK(metrics->GetMissing() == 1);
  CHECK(metrics->GetMismatchRate() == 0.5);

  // Error image, 5 x 2: sample y * 5 + x, row 0 at the bottom.
  const std::string png = dir + "/penumbra_metrics_hard.png";
  CHECK(metrics->WriteErrorImage(5, 2, png.c_str()));
  vtkNew<vtkPenumbraImageIO> io;
  vtkNew<vtkImageData> image;
  CHECK(io->Read(png.c_str(), image));
  CHECK(Pixel(image, 0, 0, 255, 255, 255)); // 0 agree lit
  CHECK(Pixel(image, 1, 0, 0, 0, 0));       // 1 agree shadow
  CHECK(Pixel(image, 2, 0, 255, 0, 0));     // 2 false lit
  CHECK(Pixel(image, 3, 0, 0, 0, 255));     // 3 false shadow
  CHECK(Pixel(image, 2, 1, 255, 255, 0));   // 7 tie
  CHECK(Pixel(image, 4, 1, 64, 64, 64));    // 9 background

  // Without ties the tie sample is a false shadow; without threshold change 0.5 stays lit.
  CHECK(metrics->CompareHard(test, reference));
  CHECK(metrics->GetCandidates() == 9 && metrics->GetFalseShadow() == 3);
  CHECK(Near(metrics->GetMismatchRate(), 5.0 / 9.0));
  metrics->SetLitThreshold(0.55);
  CHECK(metrics->CompareHard(test, reference, ties));
  CHECK(metrics->GetFalseLit() == 1);
  metrics->SetLitThreshold(0.5);

  // Candidate mask: sample 2 (false lit) and 5 excluded.
  Fill(candidates, { 1, 1, 0, 1, 1, 0, 1, 1, 1, 1 });
  CHECK(metrics->CompareHard(test, reference, ties, candidates));
  CHECK(metrics->GetCandidates() == 6);
  CHECK(metrics->GetFalseLit() == 1 && metrics->GetFalseShadow() == 2);
  CHECK(Near(metrics->GetMismatchRate(), 3.0 / 6.0));
  CHECK(metrics->WriteErrorImage(5, 2, png.c_str()));
  CHECK(io->Read(png.c_str(), image));
  CHECK(Pixel(image, 2, 0, 128, 128, 128)); // excluded by the mask

  // No candidates: rate 0, not NaN.
  Fill(reference, { -1, -1, -1, -1, -1, -1, -1, -1, -1, -1 });
  CHECK(metrics->CompareHard(test, reference, ties));
  CHECK(metrics->GetCandidates() == 0 && metrics->GetMismatchRate() == 0.0);
  return EXIT_SUCCESS;
}

int Soft(const std::string& dir)
{
  vtkNew<vtkPenumbraMetrics> metrics;
  vtkNew<vtkFloatArray> test, reference;
  vtkNew<vtkUnsignedCharArray> mask, ties;
  // |errors|: 0.25, 0, 0.25, 0.5, 0, (background), 0.5
  Fill(test, { 0.25f, 0.5f, 1.0f, 0.0f, 0.25f, 0.7f, 0.875f });
  Fill(reference, { 0.0f, 0.5f, 0.75f, 0.5f, 0.25f, -1.0f, 0.375f });
  Fill(mask, { 1, 1, 1, 1, 1, 1, 0 });
  CHECK(metrics->CompareSoft(test, reference, mask));
  // Over samples 0..4: errors 0.25 0 0.25 0.5 0.
  CHECK(metrics->GetCandidates() == 5);
  CHECK(metrics->GetMAE() == 0.2);
  CHECK(Near(metrics->GetRMSE(), std::sqrt(0.375 / 5)));
  CHECK(metrics->GetMaxError() == 0.5);
  CHECK(metrics->GetP95Error() == 0.5); // rank ceil(4.75) = 5

  const std::string png = dir + "/penumbra_metrics_soft.png";
  CHECK(metrics->WriteErrorImage(7, 1, png.c_str()));
  vtkNew<vtkPenumbraImageIO> io;
  vtkNew<vtkImageData> image;
  CHECK(io->Read(png.c_str(), image));
  CHECK(Pixel(image, 3, 0, 255, 255, 255)); // the maximum
  CHECK(Pixel(image, 0, 0, 128, 128, 128)); // half the maximum (127.5 rounds up)
  CHECK(Pixel(image, 1, 0, 0, 0, 0));       // exact
  CHECK(Pixel(image, 5, 0, 40, 40, 56));    // background
  CHECK(Pixel(image, 6, 0, 40, 40, 56));    // masked

  // Ties are excluded like the mask.
  Fill(ties, { 0, 0, 0, 1, 0, 0, 0 });
  CHECK(metrics->CompareSoft(test, reference, nullptr, ties));
  CHECK(metrics->GetCandidates() == 5 && metrics->GetTies() == 1);
  CHECK(metrics->GetMAE() == 0.2); // 0.25 0 0.25 0 0.5

  // The 95th percentile is not the maximum: errors 0.01 .. 0.20 -> rank 19 -> 0.19.
  vtkNew<vtkFloatArray> ramp, zeros;
  ramp->SetNumberOfTuples(20);
  zeros->SetNumberOfTuples(20);
  for (int i = 0; i < 20; ++i)
  {
    ramp->SetValue(i, 0.01f * static_cast<float>(20 - i)); // unsorted on purpose
    zeros->SetValue(i, 0.0f);
  }
  CHECK(metrics->CompareSoft(ramp, zeros));
  CHECK(Near(metrics->GetP95Error(), 0.19));
  CHECK(Near(metrics->GetMaxError(), 0.20));
  CHECK(Near(metrics->GetMAE(), 0.105));
  return EXIT_SUCCESS;
}

int BadInput(const std::string& dir)
{
  vtkNew<vtkPenumbraMetrics> metrics;
  vtkNew<penumbra_test::ErrorCounter> errors;
  metrics->AddObserver(vtkCommand::ErrorEvent, errors);
  vtkNew<vtkFloatArray> a, b;
  Fill(a, { 1, 0, 1 });
  Fill(b, { 1, 0 });
  CHECK(!metrics->WriteErrorImage(1, 1, (dir + "/penumbra_none.png").c_str()));
  CHECK(!metrics->CompareHard(a, nullptr));
  CHECK(!metrics->CompareHard(a, b));
  CHECK(!metrics->CompareSoft(nullptr, b));
  CHECK(metrics->GetCandidates() == 0);
  Fill(b, { 1, 1, 1 });
  CHECK(metrics->CompareHard(a, b));
  CHECK(metrics->GetFalseShadow() == 1);
  CHECK(!metrics->WriteErrorImage(2, 2, (dir + "/penumbra_size.png").c_str()));
  CHECK(std::string(metrics->GetErrorMessage()).find("does not match") != std::string::npos);
  CHECK(errors->Count == 5);
  return EXIT_SUCCESS;
}
}

int TestMetrics(int argc, char* argv[])
{
  char* tmp = vtkTestUtilities::GetArgOrEnvOrDefault("-T", argc, argv, "VTK_TEMP_DIR", ".");
  const std::string dir = tmp;
  delete[] tmp;
  RUN(Hard(dir));
  RUN(Soft(dir));
  RUN(BadInput(dir));
  return EXIT_SUCCESS;
}
