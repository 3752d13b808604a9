/**
 * @class   vtkPenumbraMetrics
 * @brief   Error figures of a technique's visibility buffer against the exact reference.
 *
 * Both buffers hold one float per view sample as vtkPenumbraReference writes them: -1 for an
 * invalid (background) sample, 0..1 otherwise. Only samples with reference >= 0 are compared.
 *
 * Hard shadows (CompareHard): a value >= LitThreshold (default 0.5) counts as lit. Over the
 * candidate samples (reference >= 0, candidate mask nonzero when given, not a tie) it counts
 * false lit (test lit, reference shadowed) and false shadow (test shadowed, reference lit);
 * MismatchRate = (false lit + false shadow) / candidates, 0 without candidates. Tie samples
 * (reference ties array nonzero) are counted separately and excluded.
 *
 * Soft shadows (CompareSoft): over the same kind of samples, statistics of |test - ref|:
 * mean (MAE), root mean square (RMSE), maximum, and the 95th percentile by the nearest-rank
 * rule (the ceil(0.95 N)-th smallest error).
 *
 * A test value below 0 where the reference has a surface (the technique lost the sample) is
 * compared as it is: shadowed for hard shadows, |test - ref| >= 1 for soft ones; such
 * samples are also counted in Missing.
 *
 * WriteErrorImage() draws the last comparison, pixel (x, y) = sample y * width + x with row 0
 * at the bottom (VTK's order; the file is written top-down):
 * - hard: black = both shadowed, white = both lit, red = false lit, blue = false shadow,
 *   yellow = tie, mid grey (128) = valid sample excluded by the candidate mask, dark grey
 *   (64) = background;
 * - soft: grey level 255 * |error| / max error (black = exact; all black when the maximum is
 *   0), dark bluish grey (40, 40, 56) = background, ties and masked samples.
 *
 * Bad input (null or differently sized arrays) makes a Compare call return 0 with
 * vtkErrorMacro and GetErrorMessage(), and resets every figure to 0.
 */

#ifndef vtkPenumbraMetrics_h
#define vtkPenumbraMetrics_h

#include "vtkObject.h"
#include "vtkPenumbraAnalysisModule.h" // For export macro

#include <memory> // For std::unique_ptr

class vtkFloatArray;
class vtkUnsignedCharArray;

class VTKPENUMBRAANALYSIS_EXPORT vtkPenumbraMetrics : public vtkObject
{
public:
  static vtkPenumbraMetrics* New();
  vtkTypeMacro(vtkPenumbraMetrics, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Hard-shadow threshold: a visibility >= LitThreshold is lit. No unit. Default 0.5.
   */
  vtkSetMacro(LitThreshold, double);
  vtkGetMacro(LitThreshold, double);
  ///@}

  /**
   * Binary comparison of `test` against `reference` (one component, same number of tuples).
   * `ties` (from vtkPenumbraReference::GetTies(), nonzero = tie) and `candidates` (nonzero =
   * compare this sample, e.g. samples facing the light) are optional and must have the same
   * size when given. Returns 1 on success, 0 on bad input.
   */
  int CompareHard(vtkFloatArray* test, vtkFloatArray* reference,
    vtkUnsignedCharArray* ties = nullptr, vtkUnsignedCharArray* candidates = nullptr);

  /**
   * Soft comparison: |test - reference| statistics over samples with reference >= 0, `mask`
   * nonzero (when given) and `ties` zero (when given). Returns 1 on success, 0 on bad input.
   */
  int CompareSoft(vtkFloatArray* test, vtkFloatArray* reference,
    vtkUnsignedCharArray* mask = nullptr, vtkUnsignedCharArray* ties = nullptr);

  /**
   * Writes an 8-bit RGB PNG (or any format vtkPenumbraImageIO knows from the extension) of
   * the last comparison; width * height must equal its number of samples. Colours in the
   * class description. Returns 1 on success, 0 with GetErrorMessage() set.
   */
  int WriteErrorImage(int width, int height, const char* path);

  ///@{
  /**
   * Sample counts of the last comparison (0 before any and after a failed one).
   * Candidates: samples compared, in both modes. Ties: tie samples excluded from the
   * comparison. Missing: compared samples that the test marked invalid (< 0).
   */
  vtkGetMacro(Candidates, vtkIdType);
  vtkGetMacro(Ties, vtkIdType);
  vtkGetMacro(Missing, vtkIdType);
  ///@}

  ///@{
  /**
   * Hard comparison. FalseLit: samples lit in the test but shadowed in the reference.
   * FalseShadow: shadowed in the test but lit in the reference. MismatchRate:
   * (FalseLit + FalseShadow) / Candidates, a fraction in [0, 1], 0 without candidates.
   */
  vtkGetMacro(FalseLit, vtkIdType);
  vtkGetMacro(FalseShadow, vtkIdType);
  vtkGetMacro(MismatchRate, double);
  ///@}

  ///@{
  /**
   * Soft comparison, in visibility units (fraction of the light) over the Candidates:
   * MAE = mean |test - reference|, RMSE = root mean square of it, MaxError = its maximum,
   * P95Error = its 95th percentile by the nearest-rank rule. All 0 without samples.
   */
  vtkGetMacro(MAE, double);
  vtkGetMacro(RMSE, double);
  vtkGetMacro(MaxError, double);
  vtkGetMacro(P95Error, double);
  ///@}

  /**
   * Why the last call failed; empty after a success.
   */
  const char* GetErrorMessage();

protected:
  vtkPenumbraMetrics();
  ~vtkPenumbraMetrics() override;

  double LitThreshold;
  vtkIdType Candidates;
  vtkIdType Ties;
  vtkIdType Missing;
  vtkIdType FalseLit;
  vtkIdType FalseShadow;
  double MismatchRate;
  double MAE;
  double RMSE;
  double MaxError;
  double P95Error;

private:
  vtkPenumbraMetrics(const vtkPenumbraMetrics&) = delete;
  void operator=(const vtkPenumbraMetrics&) = delete;

  void Reset();
  int Fail(const char* message);

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
