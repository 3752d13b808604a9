/**
 * @class   vtkPenumbraImageCompare
 * @brief   Regression-image check: compares an image file with a baseline, OpenImageIO style.
 *
 * The comparison is OpenImageIO's `ImageBufAlgo::compare`, the same as its `idiff` tool
 * (`idiff -fail T -failpercent P image baseline`), so a user can reproduce any verdict with a
 * tool from openimageio-tools: a pixel fails when any channel differs by more than Threshold
 * (values in [0, 1], so 8-bit values differ by more than Threshold x 255); the images match
 * when they have the same size and channels and at most FailFraction of their pixels fail.
 * This was chosen over VTK's vtkImageDifference because that filter's "error" is a sum over a
 * neighbourhood search that forgives one-pixel shifts and has no per-pixel meaning: a shadow
 * edge moved by a pixel (acne, a bias change) is exactly what a shadow baseline must catch.
 *
 * On a mismatch, WriteDifference() writes |image - baseline| scaled so that Threshold shows
 * as mid grey (brighter: worse), for a reviewer to see where the images differ.
 */

#ifndef vtkPenumbraImageCompare_h
#define vtkPenumbraImageCompare_h

#include "vtkObject.h"
#include "vtkPenumbraAnalysisModule.h" // For export macro

#include <memory> // For std::unique_ptr

class VTKPENUMBRAANALYSIS_EXPORT vtkPenumbraImageCompare : public vtkObject
{
public:
  static vtkPenumbraImageCompare* New();
  vtkTypeMacro(vtkPenumbraImageCompare, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Largest per-channel difference a pixel may have and still pass, with values in [0, 1].
   * Default 0.02 (5 of 255): exact techniques match bit for bit across EGL and OSMesa, and
   * this leaves room for the last bits of shading on other drivers.
   */
  vtkSetClampMacro(Threshold, double, 0.0, 1.0);
  vtkGetMacro(Threshold, double);
  ///@}

  ///@{
  /**
   * Fraction of pixels (0..1) allowed to fail before the images mismatch. Default 0: any
   * failing pixel is a mismatch.
   */
  vtkSetClampMacro(FailFraction, double, 0.0, 1.0);
  vtkGetMacro(FailFraction, double);
  ///@}

  /**
   * Compares the image file `image` with the baseline file `baseline`. Returns 1 if they
   * match, 0 if they do not (GetMessage() says how), -1 if a file cannot be read or the sizes
   * or channel counts differ (GetMessage() says which).
   */
  int Compare(const char* image, const char* baseline);

  /**
   * Writes the difference image of the last Compare() to `path` (PNG or any OpenImageIO
   * format). Returns 1 on success, 0 with GetMessage() set.
   */
  int WriteDifference(const char* path);

  /**
   * One line describing the last Compare(): the verdict, the failing pixels and the error
   * statistics, or why the comparison could not be made.
   */
  const char* GetMessage();

  ///@{
  /**
   * Statistics of the last Compare() (0 before one): failing pixels, all pixels, mean and
   * largest per-channel difference (0..1), peak signal-to-noise ratio in dB, and the pixel of
   * the largest difference (x right, y down, as in the file).
   */
  vtkGetMacro(NumberOfFailedPixels, vtkIdType);
  vtkGetMacro(NumberOfPixels, vtkIdType);
  vtkGetMacro(MeanError, double);
  vtkGetMacro(MaxError, double);
  vtkGetMacro(PSNR, double);
  vtkGetVector2Macro(MaxErrorPixel, int);
  ///@}

protected:
  vtkPenumbraImageCompare();
  ~vtkPenumbraImageCompare() override;

  double Threshold = 0.02;
  double FailFraction = 0.0;
  vtkIdType NumberOfFailedPixels = 0;
  vtkIdType NumberOfPixels = 0;
  double MeanError = 0.0;
  double MaxError = 0.0;
  double PSNR = 0.0;
  int MaxErrorPixel[2] = { 0, 0 };

private:
  vtkPenumbraImageCompare(const vtkPenumbraImageCompare&) = delete;
  void operator=(const vtkPenumbraImageCompare&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
