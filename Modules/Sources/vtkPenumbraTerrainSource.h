/**
 * @class   vtkPenumbraTerrainSource
 * @brief   Triangulated height field from a USGS DEM file, in georeferenced coordinates.
 *
 * Reads FileName with vtkDEMReader and makes a surface of triangles whose points are
 * (x, y, VerticalScale * elevation): x and y are the DEM's planimetric coordinates (e.g.
 * UTM metres, around 5.6e5 / 5.1e6 for SainteHelens.dem) kept in double precision, and the
 * elevation is the absolute value from the file (sea-level reference). vtkDEMReader puts
 * its image plane at z = minimum elevation; that offset is deliberately not added, so z is
 * not double counted as it would be by warping that image by its scalars.
 *
 * SampleRate n keeps every n-th sample along x and y, plus the last row and column, so the
 * surface always covers the full extent of the DEM. Each grid cell becomes two triangles,
 * counter-clockwise seen from above. Point normals ("Normals") come from central
 * differences of the sampled, scaled heights and point upward.
 *
 * Elevations are used as stored (in the DEM's elevation unit; metres for
 * SainteHelens.dem). A missing or unreadable file, or invalid parameters, make RequestData
 * report an error and leave the output empty.
 */

#ifndef vtkPenumbraTerrainSource_h
#define vtkPenumbraTerrainSource_h

#include "vtkPenumbraSourcesModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

class VTKPENUMBRASOURCES_EXPORT vtkPenumbraTerrainSource : public vtkPolyDataAlgorithm
{
public:
  static vtkPenumbraTerrainSource* New();
  vtkTypeMacro(vtkPenumbraTerrainSource, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * USGS DEM file to read. Default nullptr; must be set.
   */
  vtkSetFilePathMacro(FileName);
  vtkGetFilePathMacro(FileName);
  ///@}

  ///@{
  /**
   * Factor applied to elevations (dimensionless; > 1 exaggerates relief). Must be finite
   * and > 0. Default 1.
   */
  vtkSetMacro(VerticalScale, double);
  vtkGetMacro(VerticalScale, double);
  ///@}

  ///@{
  /**
   * Keep every SampleRate-th DEM sample along x and y (>= 1; 1 keeps all). Default 1
   * sample. The last row and column are always kept.
   */
  vtkSetMacro(SampleRate, int);
  vtkGetMacro(SampleRate, int);
  ///@}

protected:
  vtkPenumbraTerrainSource();
  ~vtkPenumbraTerrainSource() override;

  int RequestData(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;

  char* FileName;
  double VerticalScale;
  int SampleRate;

private:
  vtkPenumbraTerrainSource(const vtkPenumbraTerrainSource&) = delete;
  void operator=(const vtkPenumbraTerrainSource&) = delete;
};

#endif
