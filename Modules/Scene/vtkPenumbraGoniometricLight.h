/**
 * @class   vtkPenumbraGoniometricLight
 * @brief   A point light whose intensity varies with direction, from a tabulated goniometric
 *          diagram (monochrome), as in Brabec, "Shadow Techniques for Interactive and
 *          Real-Time Applications", PhD thesis, 2003, §8.3.1.
 *
 * For VTK's own shading it is an ordinary positional light (cone angle 180 by default). The
 * direction-dependent part is a relative intensity in [0, 1] that shadow techniques apply to
 * their visibility (vtkPenumbraShadowVolumeShadows does), exactly as Brabec 2003, ch. 8 scales
 * the shadow mask by the diagram's value.
 *
 * Frame. The axis A is FocalPoint - Position (transformed, unit). The polar angle theta is
 * measured from A, in degrees [0, 180]. The azimuth phi, in degrees [0, 360), is measured
 * around A from U = Up made perpendicular to A, toward V = A x U. Up defaults to (0, 0, 1);
 * when Up is parallel to A, (1, 0, 0) is used instead.
 *
 * Table. Intensities I(theta_i, phi_j) >= 0 on increasing angle lists, theta_0 = 0 and
 * phi_0 = 0 (one phi value: rotationally symmetric). A direction is looked up bilinearly,
 * phi wrapping from the last value back to 360 = phi_0; beyond the last theta the light
 * emits nothing. GetRelativeIntensity() divides by the largest table value.
 *
 * File format (text, '#' starts a comment line, numbers separated by white space):
 * @verbatim
 * penumbra-goniometric 1
 * theta N  t_0 ... t_{N-1}          (degrees, t_0 = 0, increasing, t_{N-1} <= 180)
 * phi   M  p_0 ... p_{M-1}          (degrees, p_0 = 0, increasing, p_{M-1} < 360)
 * N rows of M intensities (row i: theta_i, column j: phi_j), non-negative, not all zero
 * @endverbatim
 * Data/Lights/spot_pattern.gonio is an example.
 */

#ifndef vtkPenumbraGoniometricLight_h
#define vtkPenumbraGoniometricLight_h

#include "vtkLight.h"
#include "vtkPenumbraSceneModule.h" // For export macro

#include <string> // For the error message
#include <vector> // For the table

class VTKPENUMBRASCENE_EXPORT vtkPenumbraGoniometricLight : public vtkLight
{
public:
  static vtkPenumbraGoniometricLight* New();
  vtkTypeMacro(vtkPenumbraGoniometricLight, vtkLight);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Direction that fixes phi = 0 (see the class description). Default (0, 0, 1).
   */
  vtkSetVector3Macro(Up, double);
  vtkGetVector3Macro(Up, double);
  ///@}

  /**
   * Reads a table file (format in the class description). Returns 1 on success; 0 with
   * GetErrorMessage() set (and the table unchanged) otherwise.
   */
  int ReadFile(const char* fileName);

  /**
   * Sets the table directly: theta and phi in degrees, intensities row-major (theta rows,
   * phi columns). Returns 1 on success, 0 (table unchanged, GetErrorMessage()) on bad input.
   */
  int SetTable(const std::vector<double>& theta, const std::vector<double>& phi,
    const std::vector<double>& intensities);

  /**
   * Relative intensity in [0, 1] toward world direction `direction` (from the light, need
   * not be unit): the table value over the table maximum; 1 without a table; 0 for a zero
   * direction.
   */
  double GetRelativeIntensity(const double direction[3]);

  /**
   * Why the last ReadFile / SetTable failed; empty after a success.
   */
  const char* GetErrorMessage() { return this->ErrorMessage.c_str(); }

  /**
   * True when a table is set.
   */
  bool HasTable() { return !this->Theta.empty(); }

protected:
  vtkPenumbraGoniometricLight();
  ~vtkPenumbraGoniometricLight() override = default;

  double Up[3] = { 0.0, 0.0, 1.0 };
  std::vector<double> Theta;
  std::vector<double> Phi;
  std::vector<double> Intensities;
  double MaxIntensity = 1.0;
  std::string ErrorMessage;

private:
  vtkPenumbraGoniometricLight(const vtkPenumbraGoniometricLight&) = delete;
  void operator=(const vtkPenumbraGoniometricLight&) = delete;
};

#endif
