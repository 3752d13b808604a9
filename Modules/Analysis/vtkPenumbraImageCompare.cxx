#include "vtkPenumbraImageCompare.h"

#include "vtkObjectFactory.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <cmath>
#include <sstream>
#include <string>

struct vtkPenumbraImageCompare::Internals
{
  OIIO::ImageBuf Difference;
  std::string Message;
};

vtkStandardNewMacro(vtkPenumbraImageCompare);

vtkPenumbraImageCompare::vtkPenumbraImageCompare()
  : Impl(new Internals)
{
}

vtkPenumbraImageCompare::~vtkPenumbraImageCompare() = default;

int vtkPenumbraImageCompare::Compare(const char* image, const char* baseline)
{
  Internals& impl = *this->Impl;
  impl.Difference.reset();
  this->NumberOfFailedPixels = this->NumberOfPixels = 0;
  this->MeanError = this->MaxError = this->PSNR = 0.0;
  this->MaxErrorPixel[0] = this->MaxErrorPixel[1] = 0;
  if (!image || !baseline)
  {
    impl.Message = "no image or no baseline given";
    return -1;
  }
  // Read as float in [0, 1] whatever the file's bit depth, so Threshold means the same.
  OIIO::ImageBuf a(image), b(baseline);
  for (auto* buf : { &a, &b })
  {
    if (!buf->read(0, 0, true, OIIO::TypeDesc::FLOAT))
    {
      impl.Message =
        std::string(buf == &a ? image : baseline) + ": cannot read: " + buf->geterror();
      return -1;
    }
  }
  const OIIO::ImageSpec& sa = a.spec();
  const OIIO::ImageSpec& sb = b.spec();
  if (sa.width != sb.width || sa.height != sb.height || sa.nchannels != sb.nchannels)
  {
    std::ostringstream msg;
    msg << image << " is " << sa.width << "x" << sa.height << " with " << sa.nchannels
        << " channels, the baseline " << baseline << " is " << sb.width << "x" << sb.height
        << " with " << sb.nchannels;
    impl.Message = msg.str();
    return -1;
  }
  const auto r = OIIO::ImageBufAlgo::compare(
    a, b, static_cast<float>(this->Threshold), static_cast<float>(this->Threshold));
  // OpenImageIO 2.4 sets r.error whenever some pixel fails; reading errors and size
  // mismatches were ruled out above, so nfail alone decides.
  this->NumberOfPixels = static_cast<vtkIdType>(sa.width) * sa.height;
  this->NumberOfFailedPixels = static_cast<vtkIdType>(r.nfail);
  this->MeanError = r.meanerror;
  this->MaxError = r.maxerror;
  this->PSNR = r.PSNR;
  this->MaxErrorPixel[0] = r.maxx;
  this->MaxErrorPixel[1] = r.maxy;
  // |A - B| scaled so that the threshold is mid grey.
  const float scale = static_cast<float>(0.5 / std::max(this->Threshold, 1.0 / 255.0));
  impl.Difference = OIIO::ImageBufAlgo::mul(OIIO::ImageBufAlgo::absdiff(a, b), scale);

  const bool match =
    this->NumberOfFailedPixels <= this->FailFraction * static_cast<double>(this->NumberOfPixels);
  std::ostringstream msg;
  msg << (match ? "matches " : "differs from ") << baseline << ": " << this->NumberOfFailedPixels
      << " of " << this->NumberOfPixels << " pixels differ by more than " << this->Threshold
      << " (allowed " << this->FailFraction * 100.0 << "%); mean error " << this->MeanError
      << ", max " << this->MaxError << " at (" << r.maxx << ", " << r.maxy << "), PSNR "
      << this->PSNR << " dB";
  impl.Message = msg.str();
  return match ? 1 : 0;
}

int vtkPenumbraImageCompare::WriteDifference(const char* path)
{
  Internals& impl = *this->Impl;
  if (!impl.Difference.initialized())
  {
    impl.Message = "no comparison to write a difference image of";
    return 0;
  }
  // 8-bit output: the scaled difference is clamped to white.
  OIIO::ImageBuf clamped = OIIO::ImageBufAlgo::clamp(impl.Difference, 0.0f, 1.0f);
  if (!path || !clamped.write(path, OIIO::TypeDesc::UINT8))
  {
    impl.Message = std::string(path ? path : "(none)") +
      ": cannot write the difference image: " + clamped.geterror();
    return 0;
  }
  return 1;
}

const char* vtkPenumbraImageCompare::GetMessage()
{
  return this->Impl->Message.c_str();
}

void vtkPenumbraImageCompare::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Threshold: " << this->Threshold << "\n";
  os << indent << "FailFraction: " << this->FailFraction << "\n";
  os << indent << "Message: " << this->Impl->Message << "\n";
}
