#include "vtkPenumbraImageIO.h"

#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtksys/SystemTools.hxx"

#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <unistd.h>

vtkStandardNewMacro(vtkPenumbraImageIO);

int vtkPenumbraImageIO::Write(vtkImageData* image, const char* path)
{
  this->ErrorMessage.clear();
  if (!path || !*path)
  {
    this->ErrorMessage = "no output file name";
    return 0;
  }
  vtkDataArray* scalars = image ? image->GetPointData()->GetScalars() : nullptr;
  int dims[3] = { 0, 0, 0 };
  if (image)
  {
    image->GetDimensions(dims);
  }
  if (!scalars || dims[0] < 1 || dims[1] < 1 || dims[2] != 1)
  {
    this->ErrorMessage = std::string(path) + ": nothing to write (no 2-D image with pixels)";
    return 0;
  }
  const int channels = scalars->GetNumberOfComponents();
  OIIO::TypeDesc type;
  switch (scalars->GetDataType())
  {
    case VTK_UNSIGNED_CHAR:
      type = OIIO::TypeDesc::UINT8;
      break;
    case VTK_FLOAT:
      type = OIIO::TypeDesc::FLOAT;
      break;
    default:
      this->ErrorMessage = std::string(path) + ": only unsigned char and float images are written";
      return 0;
  }
  if (channels < 1 || channels > 4)
  {
    this->ErrorMessage = std::string(path) + ": 1 to 4 components expected";
    return 0;
  }

  // Temporary file in the target's folder, same extension so OIIO picks the format.
  const std::string target = path;
  const std::string ext = vtksys::SystemTools::GetFilenameLastExtension(target);
  const std::string temp =
    vtksys::SystemTools::GetFilenamePath(vtksys::SystemTools::CollapseFullPath(target)) + "/." +
    vtksys::SystemTools::GetFilenameWithoutLastExtension(target) + ".partial." +
    std::to_string(static_cast<long>(getpid())) + ext;

  auto out = OIIO::ImageOutput::create(target);
  if (!out)
  {
    this->ErrorMessage = target + ": cannot write this image format (" + OIIO::geterror() + ")";
    return 0;
  }
  OIIO::ImageSpec spec(dims[0], dims[1], channels, type);
  const size_t pixelBytes = static_cast<size_t>(channels) * type.size();
  const OIIO::stride_t rowBytes = static_cast<OIIO::stride_t>(pixelBytes) * dims[0];
  // VTK's first row is the bottom one: start at the last row and walk upwards.
  const char* bottom = static_cast<const char*>(scalars->GetVoidPointer(0));
  const char* top = bottom + rowBytes * (dims[1] - 1);
  const bool ok = out->open(temp, spec) &&
    out->write_image(type, top, static_cast<OIIO::stride_t>(pixelBytes), -rowBytes) && out->close();
  if (!ok)
  {
    this->ErrorMessage = target + ": write failed: " + out->geterror();
    std::remove(temp.c_str());
    return 0;
  }
  if (std::rename(temp.c_str(), target.c_str()) != 0)
  {
    this->ErrorMessage = target + ": cannot move the finished image into place";
    std::remove(temp.c_str());
    return 0;
  }
  return 1;
}

int vtkPenumbraImageIO::Read(const char* path, vtkImageData* image)
{
  this->ErrorMessage.clear();
  if (!path || !image)
  {
    this->ErrorMessage = "no file name or no image to read into";
    return 0;
  }
  auto in = OIIO::ImageInput::open(path);
  if (!in)
  {
    this->ErrorMessage = std::string(path) + ": cannot read: " + OIIO::geterror();
    return 0;
  }
  const OIIO::ImageSpec& spec = in->spec();
  const bool byte = spec.format == OIIO::TypeDesc::UINT8;
  const OIIO::TypeDesc type = byte ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT;
  image->SetDimensions(spec.width, spec.height, 1);
  image->AllocateScalars(byte ? VTK_UNSIGNED_CHAR : VTK_FLOAT, spec.nchannels);
  const size_t pixelBytes = static_cast<size_t>(spec.nchannels) * type.size();
  const OIIO::stride_t rowBytes = static_cast<OIIO::stride_t>(pixelBytes) * spec.width;
  char* bottom = static_cast<char*>(image->GetScalarPointer());
  char* top = bottom + rowBytes * (spec.height - 1);
  const bool ok = in->read_image(
    0, 0, 0, spec.nchannels, type, top, static_cast<OIIO::stride_t>(pixelBytes), -rowBytes);
  if (!ok)
  {
    this->ErrorMessage = std::string(path) + ": read failed: " + in->geterror();
    return 0;
  }
  in->close();
  return 1;
}
