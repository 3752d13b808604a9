/**
 * @class   vtkPenumbraAreaLight
 * @brief   Rectangular or linear light source for soft shadows.
 *
 * A vtkLight with an extent. The light's Position is the centre of the emitter and
 * FocalPoint - Position its emission direction (the normal of a rectangle). Up fixes the
 * in-plane orientation: the V axis is Up made perpendicular to the normal, and U = V x N.
 *
 * For ordinary VTK shading the light behaves as a positional light at its centre with a
 * 180 degree cone, so a renderer without a soft-shadow technique still lights the scene
 * sensibly.
 *
 * Light samples. Soft-shadow techniques and the exact reference must agree on *where* the
 * light is sampled, so the positions are fixed here: with k = SamplesPerAxis, a rectangle
 * has k*k samples at the centres of a regular k x k grid of cells, index = j*k + i at
 *   Position + ((i + 0.5)/k - 0.5) * Width * U + ((j + 0.5)/k - 0.5) * Height * V,
 * and a line has k samples at Position + ((i + 0.5)/k - 0.5) * Length * U (Length = Width).
 *
 * A TransformMatrix (VTK's light transform, e.g. for camera lights) moves the emitter: the
 * centre is GetTransformedPosition(), the frame comes from the transformed position and
 * focal point and the Up direction turned by the matrix. It must be a rigid motion (the
 * size is in world units); GetValidityMessage() rejects a scaling or projective one.
 */

#ifndef vtkPenumbraAreaLight_h
#define vtkPenumbraAreaLight_h

#include "vtkLight.h"
#include "vtkPenumbraSceneModule.h" // For export macro

class VTKPENUMBRASCENE_EXPORT vtkPenumbraAreaLight : public vtkLight
{
public:
  static vtkPenumbraAreaLight* New();
  vtkTypeMacro(vtkPenumbraAreaLight, vtkLight);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum ShapeType
  {
    Rectangle = 0,
    Line = 1
  };

  ///@{
  /**
   * Shape of the emitter: Rectangle (default) or Line.
   */
  vtkSetClampMacro(Shape, int, Rectangle, Line);
  vtkGetMacro(Shape, int);
  void SetShapeToRectangle() { this->SetShape(Rectangle); }
  void SetShapeToLine() { this->SetShape(Line); }
  ///@}

  ///@{
  /**
   * Extent along U (the length of a Line), in world units (metres in the scene files).
   * Default 1. Must be positive and finite.
   */
  vtkSetMacro(Width, double);
  vtkGetMacro(Width, double);
  ///@}

  ///@{
  /**
   * Extent along V, in world units; ignored for a Line. Default 1. Must be positive and
   * finite for a Rectangle.
   */
  vtkSetMacro(Height, double);
  vtkGetMacro(Height, double);
  ///@}

  ///@{
  /**
   * Direction that, made perpendicular to the emission direction, becomes the V axis.
   * Default (0, 0, 1); if it is parallel to the emission direction another axis is used.
   */
  vtkSetVector3Macro(Up, double);
  vtkGetVector3Macro(Up, double);
  ///@}

  ///@{
  /**
   * Samples per axis k: k*k light samples for a Rectangle, k for a Line. Default 8,
   * clamped to [1, 64].
   */
  vtkSetClampMacro(SamplesPerAxis, int, 1, 64);
  vtkGetMacro(SamplesPerAxis, int);
  ///@}

  /**
   * k*k for a Rectangle, k for a Line.
   */
  int GetNumberOfSamples();

  /**
   * World position of light sample `index` (see the class description). Returns false for
   * an index out of range.
   */
  bool GetSamplePosition(int index, double position[3]);

  /**
   * Centre of the emitter in world coordinates: the Position through the TransformMatrix.
   */
  void GetCentre(double centre[3]);

  /**
   * Orthonormal frame of the emitter: U, V in its plane and N its emission direction.
   * Returns false if the light has no direction (Position == FocalPoint).
   */
  bool GetAxes(double u[3], double v[3], double n[3]);

  /**
   * Empty if the light is usable; otherwise why not (zero or negative size, NaN, no
   * direction).
   */
  const char* GetValidityMessage();

  vtkLight* ShallowClone() override;

protected:
  // True without a TransformMatrix or with a rotation + translation.
  bool IsRigid();

  vtkPenumbraAreaLight();
  ~vtkPenumbraAreaLight() override = default;

  int Shape;
  double Width;
  double Height;
  double Up[3];
  int SamplesPerAxis;

private:
  vtkPenumbraAreaLight(const vtkPenumbraAreaLight&) = delete;
  void operator=(const vtkPenumbraAreaLight&) = delete;

  char ValidityMessage[256];
};

#endif
