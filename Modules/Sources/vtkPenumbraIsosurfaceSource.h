/**
 * @class   vtkPenumbraIsosurfaceSource
 * @brief   Isosurface of a procedural or file-based 3-D scalar field, as triangles with normals.
 *
 * With no FileName (the default) the field is procedural: a sum of Gaussian blobs and a
 * Gaussian tube around a horizontal ring, sampled on a Resolution^3 grid that spans
 * Bounds. The field is defined on [-1, 1]^3 and stretched to Bounds, so the shapes fill
 * whatever box is asked for. At the default IsoValue of 0.5 the surface has five closed
 * components (a torus, a blob over its hole, a two-lobed blob under it and two satellites)
 * that shadow each other.
 *
 * With FileName set, the file is read as a volume (legacy ".vtk" structured points, or
 * XML ".vti" image data; chosen by extension, case-insensitively) and its active point
 * scalars (first component) are contoured at IsoValue. Resolution and Bounds are then
 * ignored; the surface is in the volume's own coordinates.
 *
 * Contouring uses vtkContourFilter. The output holds only triangles, with point normals
 * ("Normals") pointing from higher toward lower scalar values, i.e. out of the blobs.
 * Invalid parameters, missing or unreadable files make RequestData report an error and
 * leave the output empty. An IsoValue outside the data range gives an empty surface
 * without error.
 */

#ifndef vtkPenumbraIsosurfaceSource_h
#define vtkPenumbraIsosurfaceSource_h

#include "vtkPenumbraSourcesModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

class vtkImageData;

class VTKPENUMBRASOURCES_EXPORT vtkPenumbraIsosurfaceSource : public vtkPolyDataAlgorithm
{
public:
  static vtkPenumbraIsosurfaceSource* New();
  vtkTypeMacro(vtkPenumbraIsosurfaceSource, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Volume file to contour instead of the procedural field (".vtk" legacy structured
   * points or ".vti"). Default nullptr (empty): procedural field.
   */
  vtkSetFilePathMacro(FileName);
  vtkGetFilePathMacro(FileName);
  ///@}

  ///@{
  /**
   * Scalar value of the surface, in the field's units (dimensionless for the procedural
   * field, whose peaks are about 1). Must be finite. Default 0.5, which suits the
   * procedural field; set it for files (e.g. 90 for the carotid volume).
   */
  vtkSetMacro(IsoValue, double);
  vtkGetMacro(IsoValue, double);
  ///@}

  ///@{
  /**
   * Procedural mode only: number of grid samples along each axis, in [2, 1024].
   * Default 48 samples.
   */
  vtkSetMacro(Resolution, int);
  vtkGetMacro(Resolution, int);
  ///@}

  ///@{
  /**
   * Procedural mode only: box (xmin, xmax, ymin, ymax, zmin, zmax) the field is sampled
   * in, in world units (metres in Penumbra scenes); finite with min < max on each axis.
   * Default (-1, 1, -1, 1, -1, 1).
   */
  vtkSetVector6Macro(Bounds, double);
  vtkGetVector6Macro(Bounds, double);
  ///@}

protected:
  vtkPenumbraIsosurfaceSource();
  ~vtkPenumbraIsosurfaceSource() override;

  int RequestData(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;

  char* FileName;
  double IsoValue;
  int Resolution;
  double Bounds[6];

private:
  vtkPenumbraIsosurfaceSource(const vtkPenumbraIsosurfaceSource&) = delete;
  void operator=(const vtkPenumbraIsosurfaceSource&) = delete;

  bool MakeProceduralVolume(vtkImageData* volume);
  bool ReadVolume(vtkImageData* volume);
};

#endif
