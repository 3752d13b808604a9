// Image files round-trip exactly (8-bit PNG and float EXR), keep VTK's bottom-up row order,
// and a failed write leaves no file behind.
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPenumbraImageIO.h"
#include "vtkTestUtilities.h"
#include "vtksys/SystemTools.hxx"

#include <cstdlib>
#include <iostream>
#include <string>

#include "PenumbraTestMacros.h"

int TestImageIO(int argc, char* argv[])
{
  char* tmp = vtkTestUtilities::GetArgOrEnvOrDefault("-T", argc, argv, "VTK_TEMP_DIR", ".");
  const std::string dir = tmp;
  delete[] tmp;
  vtksys::SystemTools::MakeDirectory(dir);

  // 8-bit RGB with a distinct value per pixel; row 0 (bottom in VTK) is pure red.
  vtkNew<vtkImageData> rgb;
  rgb->SetDimensions(7, 5, 1);
  rgb->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto* px = static_cast<unsigned char*>(rgb->GetScalarPointer());
  for (int i = 0; i < 7 * 5; ++i)
  {
    px[3 * i + 0] = static_cast<unsigned char>(i < 7 ? 255 : 7 * i);
    px[3 * i + 1] = static_cast<unsigned char>(i < 7 ? 0 : 3 * i);
    px[3 * i + 2] = static_cast<unsigned char>(i < 7 ? 0 : 255 - i);
  }
  vtkNew<vtkPenumbraImageIO> io;
  const std::string png = dir + "/penumbra_io_test.png";
  CHECK(io->Write(rgb, png.c_str()));
  vtkNew<vtkImageData> back;
  CHECK(io->Read(png.c_str(), back));
  int dims[3];
  back->GetDimensions(dims);
  CHECK(dims[0] == 7 && dims[1] == 5 && back->GetNumberOfScalarComponents() == 3);
  auto* got = static_cast<unsigned char*>(back->GetScalarPointer());
  for (int i = 0; i < 7 * 5 * 3; ++i)
  {
    CHECK(got[i] == px[i]);
  }

  // Float, one channel: exact round trip through OpenEXR.
  vtkNew<vtkImageData> mask;
  mask->SetDimensions(4, 3, 1);
  mask->AllocateScalars(VTK_FLOAT, 1);
  auto* f = static_cast<float*>(mask->GetScalarPointer());
  for (int i = 0; i < 12; ++i)
  {
    f[i] = 0.125f * static_cast<float>(i) - 0.3f;
  }
  const std::string exr = dir + "/penumbra_io_test.exr";
  CHECK(io->Write(mask, exr.c_str()));
  vtkNew<vtkImageData> maskBack;
  CHECK(io->Read(exr.c_str(), maskBack));
  auto* g = static_cast<float*>(maskBack->GetScalarPointer());
  for (int i = 0; i < 12; ++i)
  {
    CHECK(g[i] == f[i]);
  }

  // Failures: no folder, no pixels, unknown format. Nothing may be left behind.
  const std::string missing = dir + "/no_such_folder/x.png";
  CHECK(!io->Write(rgb, missing.c_str()));
  CHECK(!vtksys::SystemTools::FileExists(missing));
  vtkNew<vtkImageData> empty;
  const std::string emptyPath = dir + "/penumbra_empty.png";
  CHECK(!io->Write(empty, emptyPath.c_str()));
  CHECK(!vtksys::SystemTools::FileExists(emptyPath));
  CHECK(!io->Write(rgb, (dir + "/x.notaformat").c_str()));
  CHECK(!io->Read((dir + "/does_not_exist.png").c_str(), back));
  CHECK(std::string(io->GetErrorMessage()).find("does_not_exist.png") != std::string::npos);
  return EXIT_SUCCESS;
}
