/**
 * @class   vtkPenumbraImageIO
 * @brief   Image files through OpenImageIO: atomic writes, reads into vtkImageData.
 *
 * VTK images have their origin at the bottom-left, image files at the top-left; both
 * functions flip rows so that a written image reads back identical. Writes go to a temporary
 * file next to the target that is renamed into place only when complete, so a failed or
 * interrupted write never leaves a partial image behind.
 */

#ifndef vtkPenumbraImageIO_h
#define vtkPenumbraImageIO_h

#include "vtkObject.h"
#include "vtkPenumbraAnalysisModule.h" // For export macro

#include <string> // For std::string

class vtkImageData;

class VTKPENUMBRAANALYSIS_EXPORT vtkPenumbraImageIO : public vtkObject
{
public:
  static vtkPenumbraImageIO* New();
  vtkTypeMacro(vtkPenumbraImageIO, vtkObject);

  /**
   * Writes an unsigned-char or float image (1..4 components, 2-D) to `path`; the format
   * follows the extension (.png, .exr, .tif, ...). Returns 1 on success; 0 with
   * GetErrorMessage() set and no file written.
   */
  int Write(vtkImageData* image, const char* path);

  /**
   * Reads `path` into `image` (unsigned char for 8-bit files, float otherwise). Returns 1 on
   * success; 0 with GetErrorMessage() set.
   */
  int Read(const char* path, vtkImageData* image);

  const char* GetErrorMessage() { return this->ErrorMessage.c_str(); }

protected:
  vtkPenumbraImageIO() = default;
  ~vtkPenumbraImageIO() override = default;

private:
  vtkPenumbraImageIO(const vtkPenumbraImageIO&) = delete;
  void operator=(const vtkPenumbraImageIO&) = delete;

  std::string ErrorMessage;
};

#endif
