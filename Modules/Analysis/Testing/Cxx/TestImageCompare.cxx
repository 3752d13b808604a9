// vtkPenumbraImageCompare: idiff semantics on small images whose differences are known — one
// pixel over the threshold fails, the allowed fraction and the threshold forgive it, a size
// mismatch or a missing file is an error, and the difference image marks the pixel.
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPenumbraImageCompare.h"
#include "vtkPenumbraImageIO.h"
#include "vtkTestUtilities.h"
#include "vtksys/SystemTools.hxx"

#include <cstdlib>
#include <iostream>
#include <string>

#include "PenumbraTestMacros.h"

namespace
{
// A w x h grey RGB image with pixel (x, y) (VTK's bottom-up rows) raised by `delta`.
std::string Image(const std::string& path, int w, int h, int x, int y, int delta)
{
  vtkNew<vtkImageData> image;
  image->SetDimensions(w, h, 1);
  image->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto* px = static_cast<unsigned char*>(image->GetScalarPointer());
  for (int i = 0; i < 3 * w * h; ++i)
  {
    px[i] = 100;
  }
  px[3 * (y * w + x) + 1] = static_cast<unsigned char>(100 + delta);
  vtkNew<vtkPenumbraImageIO> io;
  io->Write(image, path.c_str());
  return path;
}
}

int TestImageCompare(int argc, char* argv[])
{
  char* tmp = vtkTestUtilities::GetArgOrEnvOrDefault("-T", argc, argv, "VTK_TEMP_DIR", ".");
  const std::string dir = tmp;
  delete[] tmp;
  vtksys::SystemTools::MakeDirectory(dir);
  const std::string base = Image(dir + "/compare_base.png", 20, 10, 0, 0, 0);
  const std::string same = Image(dir + "/compare_same.png", 20, 10, 0, 0, 0);
  // 10 of 255 on one channel of the pixel at column 3, row 2 from the bottom (row 7 in the file).
  const std::string off = Image(dir + "/compare_off.png", 20, 10, 3, 2, 10);

  vtkNew<vtkPenumbraImageCompare> compare;
  CHECK(compare->GetThreshold() == 0.02 && compare->GetFailFraction() == 0.0);
  CHECK(compare->Compare(same.c_str(), base.c_str()) == 1);
  CHECK(compare->GetNumberOfFailedPixels() == 0 && compare->GetMaxError() == 0.0);

  CHECK(compare->Compare(off.c_str(), base.c_str()) == 0);
  std::cout << compare->GetMessage() << std::endl;
  CHECK(compare->GetNumberOfFailedPixels() == 1 && compare->GetNumberOfPixels() == 200);
  CHECK(std::abs(compare->GetMaxError() - 10.0 / 255.0) < 1e-6);
  CHECK(compare->GetMaxErrorPixel()[0] == 3 && compare->GetMaxErrorPixel()[1] == 7);
  const std::string diff = dir + "/compare_diff.png";
  CHECK(compare->WriteDifference(diff.c_str()));
  vtkNew<vtkImageData> d;
  vtkNew<vtkPenumbraImageIO> io;
  CHECK(io->Read(diff.c_str(), d));
  // 10/255 at threshold 0.02 shows as about 0.98 of white; every other pixel is black.
  CHECK(*static_cast<unsigned char*>(d->GetScalarPointer(3, 2, 0)) == 0);
  CHECK(static_cast<unsigned char*>(d->GetScalarPointer(3, 2, 0))[1] > 240);
  CHECK(static_cast<unsigned char*>(d->GetScalarPointer(4, 2, 0))[1] == 0);

  compare->SetFailFraction(0.01); // 2 of 200 pixels may fail
  CHECK(compare->Compare(off.c_str(), base.c_str()) == 1);
  compare->SetFailFraction(0.0);
  compare->SetThreshold(0.05);
  CHECK(compare->Compare(off.c_str(), base.c_str()) == 1);

  const std::string small = Image(dir + "/compare_small.png", 10, 10, 0, 0, 0);
  CHECK(compare->Compare(small.c_str(), base.c_str()) == -1);
  CHECK(std::string(compare->GetMessage()).find("is 10x10 with 3 channels") != std::string::npos);
  CHECK(compare->Compare((dir + "/missing.png").c_str(), base.c_str()) == -1);
  CHECK(std::string(compare->GetMessage()).find("cannot read") != std::string::npos);
  return EXIT_SUCCESS;
}
