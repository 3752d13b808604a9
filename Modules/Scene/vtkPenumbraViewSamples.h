/**
 * @class   vtkPenumbraViewSamples
 * @brief   The view's G-buffer as CPU arrays: one surface sample per pixel.
 *
 * A technique computes a visibility value per view sample; the exact reference computes it
 * on the same samples so the two can be compared pixel by pixel. Samples are stored row-major
 * with row 0 at the bottom, like VTK images: sample = y * width + x.
 *
 * Positions are float32 relative to Origin (the vtkPenumbraSceneGeometry rebasing origin):
 * absolute float32 would lose metres at city coordinates, relative ones keep millimetres.
 * This class only holds the samples; a render pass (or a test) fills them.
 */

#ifndef vtkPenumbraViewSamples_h
#define vtkPenumbraViewSamples_h

#include "vtkObject.h"
#include "vtkPenumbraSceneModule.h" // For export macro

#include <memory> // For std::unique_ptr
#include <string> // For std::string

class vtkFloatArray;
class vtkIdTypeArray;
class vtkIntArray;

class VTKPENUMBRASCENE_EXPORT vtkPenumbraViewSamples : public vtkObject
{
public:
  static vtkPenumbraViewSamples* New();
  vtkTypeMacro(vtkPenumbraViewSamples, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Allocates every array for width x height samples and marks every sample invalid (prop
   * index -1, triangle id -1, position and normal 0). Negative sizes count as 0. Default 0 x 0.
   */
  void SetSize(int width, int height);

  /**
   * Copies every array and setting of `other` (a snapshot that later frames do not change).
   */
  void DeepCopy(vtkPenumbraViewSamples* other);

  ///@{
  /**
   * Size in samples (pixels) set by SetSize(). Default 0 x 0.
   */
  int GetWidth();
  int GetHeight();
  vtkIdType GetNumberOfSamples();
  ///@}

  ///@{
  /**
   * The rebasing origin (world coordinates, metres) the positions are relative to.
   * Default (0, 0, 0).
   */
  vtkSetVector3Macro(Origin, double);
  vtkGetVector3Macro(Origin, double);
  ///@}

  /**
   * 3 components per sample: world position minus Origin (float32, metres).
   */
  vtkFloatArray* GetPositions();

  /**
   * 3 components per sample: unit world-space normal of the surface seen, oriented toward
   * the camera.
   */
  vtkFloatArray* GetNormals();

  /**
   * 1 component per sample: index of the prop seen in the vtkPenumbraSceneGeometry prop list,
   * -1 for background / no surface.
   */
  vtkIntArray* GetPropIndices();

  /**
   * 1 component per sample: global triangle index into a vtkPenumbraSceneGeometry, -1 when
   * unknown.
   */
  vtkIdTypeArray* GetTriangleIds();

  ///@{
  /**
   * Camera position in world coordinates (metres), for orienting normals and scaling
   * offsets. Default (0, 0, 0).
   */
  vtkSetVector3Macro(CameraPosition, double);
  vtkGetVector3Macro(CameraPosition, double);
  ///@}

  /**
   * Why the arrays cannot be read as GetNumberOfSamples() samples, or "" when they can:
   * positions and normals of 3 components, prop indices and triangle ids of 1, each with
   * GetNumberOfSamples() tuples, and a finite Origin. The arrays are public, so a producer may
   * have resized or reshaped them: every consumer checks with this before reading them
   * through raw pointers.
   */
  std::string CheckArrays();

  /**
   * True when the sample index is in range and the sample sees a surface (prop index >= 0).
   */
  bool IsValid(vtkIdType sample);

  /**
   * Number of samples that see a surface.
   */
  vtkIdType GetNumberOfValidSamples();

  /**
   * Index of the sample of pixel (x, y), row 0 at the bottom; -1 when outside.
   */
  vtkIdType GetSampleIndex(int x, int y);

  /**
   * World position of a sample in double precision: position + Origin. Returns false (and
   * leaves `world` untouched) for an invalid sample.
   */
  bool GetWorldPosition(vtkIdType sample, double world[3]);

  /**
   * Sets one sample: world position (the Origin is subtracted in double before rounding to
   * float), normal (normalized, flipped toward CameraPosition), prop index and triangle id.
   * Convenient for tests and CPU producers; a GPU pass writes the arrays directly.
   */
  void SetSample(vtkIdType sample, const double world[3], const double normal[3], int propIndex,
    vtkIdType triangleId);

protected:
  vtkPenumbraViewSamples();
  ~vtkPenumbraViewSamples() override;

  double Origin[3];
  double CameraPosition[3];

private:
  vtkPenumbraViewSamples(const vtkPenumbraViewSamples&) = delete;
  void operator=(const vtkPenumbraViewSamples&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
