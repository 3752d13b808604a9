/**
 * @class   vtkPenumbraAreaLight
 * @brief   Rectangular, linear or disc-shaped light source for soft shadows.
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
 * A disc (diameter Width) keeps the cells of the k x k grid over its bounding square whose
 * centre lies inside the disc, |(su, sv)| <= Width / 2: equal cells, as a rectangle's, so every
 * technique that samples rectangles samples a disc the same way and the samples converge on
 * the disc as k grows. Its samples are numbered row by row (j, then i) over the kept cells
 * only; GetRowCells() tells which cells of a row are kept.
 *
 * A sphere light of radius r (vtkPenumbraShadowKeys::SetLightRadius on any positional
 * vtkLight, or ParaView's light Radius) is shadowed as the disc of diameter 2r through its
 * centre facing its focal point (SetFromLightRadius): the sphere's outline as seen from the
 * receivers near its axis.
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

class vtkDoubleArray;

class VTKPENUMBRASCENE_EXPORT vtkPenumbraAreaLight : public vtkLight
{
public:
  static vtkPenumbraAreaLight* New();
  vtkTypeMacro(vtkPenumbraAreaLight, vtkLight);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum ShapeType
  {
    Rectangle = 0,
    Line = 1,
    Disc = 2
  };

  ///@{
  /**
   * Shape of the emitter: Rectangle (default), Line or Disc.
   */
  vtkSetClampMacro(Shape, int, Rectangle, Disc);
  vtkGetMacro(Shape, int);
  void SetShapeToRectangle() { this->SetShape(Rectangle); }
  void SetShapeToLine() { this->SetShape(Line); }
  void SetShapeToDisc() { this->SetShape(Disc); }
  const char* GetShapeAsString();
  ///@}

  ///@{
  /**
   * Extent along U (the length of a Line, the diameter of a Disc), in world units (metres in
   * the scene files). Default 1. Must be positive and finite.
   */
  vtkSetMacro(Width, double);
  vtkGetMacro(Width, double);
  ///@}

  ///@{
  /**
   * Extent along V, in world units; ignored for a Line and a Disc. Default 1. Must be positive and
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
   * k*k for a Rectangle, k for a Line, the cells kept of the k x k grid for a Disc.
   */
  int GetNumberOfSamples();

  /**
   * World position of light sample `index` (see the class description). Returns false for
   * an index out of range.
   */
  bool GetSamplePosition(int index, double position[3]);

  /**
   * The light sampled with `samplesPerAxis` in place of SamplesPerAxis (in [1, 256]; for
   * converged references), by the same rule and expressions as GetSamplePosition(): one
   * tuple of 3 world coordinates per sample, in sample order. Returns false (positions
   * emptied) for a light without a direction or a count out of range.
   */
  bool GetSamplePositions(int samplesPerAxis, vtkDoubleArray* positions);

  /**
   * The emitter's extent along V: Height for a Rectangle, the diameter (Width) for a Disc, 0
   * for a Line. Its extent along U is Width for every shape.
   */
  double GetExtentV() const;

  /**
   * The grid rows of the samples: k for a Rectangle and a Disc, 1 for a Line.
   */
  int GetNumberOfRows();

  /**
   * The cells of grid row `row` that hold light samples, columns first..last; false (and
   * first > last) when the row holds none. All k for a Rectangle or a Line; for a Disc the
   * cells whose centre lies inside it.
   */
  bool GetRowCells(int row, int& first, int& last);

  /**
   * World position of the centre of grid cell (i, j), i, j in [0, k) (j = 0 for a Line),
   * whether or not it holds a light sample: GetSamplePosition()'s expression.
   */
  bool GetCellPosition(int i, int j, double position[3]);

  /**
   * Makes this light the disc that stands for `light` with a sphere of radius `radius`:
   * `light`'s position, focal point, transform, colour and intensity, Shape Disc of diameter
   * 2 radius facing the focal point (Up: the world axis least aligned with it). `light` must
   * be positional. Returns false (this light unchanged) for a non-positional light or a
   * radius that is not positive and finite.
   */
  bool SetFromLightRadius(vtkLight* light, double radius);

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

  // The one sampling rule: the cells of row `row` of a k x k grid (k x 1 for a Line) that
  // hold samples, for this light's shape.
  bool RowCells(int k, int row, int& first, int& last) const;
  // Centre of cell (i, j) of the k-grid from the frame's centre and axes.
  void CellPosition(int k, int i, int j, const double centre[3], const double u[3],
    const double v[3], double position[3]) const;

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
