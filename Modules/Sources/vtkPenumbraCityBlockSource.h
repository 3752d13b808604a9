/**
 * @class   vtkPenumbraCityBlockSource
 * @brief   Procedural city block: a grid of lots with one box (or gable-roofed) building each.
 *
 * The block is Rows x Columns square lots of side Spacing. Lot (row r, column c) covers
 * x in [c*Spacing, (c+1)*Spacing], y in [r*Spacing, (r+1)*Spacing] before the Origin
 * translation, so the block's lower-left lot corner is at Origin and the ground is at
 * z = Origin[2]. Every lot holds one building: a closed solid (walls, flat or gable roof and
 * a bottom face) whose footprint is a random fraction of the lot and whose top is at a
 * random height. The layout depends only on the parameters and Seed; the same parameters
 * give bit-identical output on every platform.
 *
 * The output is triangles with per-face point normals (points are not shared between
 * faces, so edges stay sharp), points in double precision so that georeferenced Origins
 * (e.g. UTM coordinates around 5e6 m) lose nothing, and the int cell array "PartId":
 * 0 for the ground, i+1 for building i (i = row*Columns + column). Threshold on PartId to
 * split shadow receivers from casters.
 *
 * Invalid parameters make RequestData report an error and leave the output empty.
 */

#ifndef vtkPenumbraCityBlockSource_h
#define vtkPenumbraCityBlockSource_h

#include "vtkPenumbraSourcesModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

class VTKPENUMBRASOURCES_EXPORT vtkPenumbraCityBlockSource : public vtkPolyDataAlgorithm
{
public:
  static vtkPenumbraCityBlockSource* New();
  vtkTypeMacro(vtkPenumbraCityBlockSource, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Number of lot rows (along y) and columns (along x). Each must be >= 1 and
   * Rows*Columns <= 1,000,000. Default 4 x 4.
   */
  vtkSetMacro(Rows, int);
  vtkGetMacro(Rows, int);
  vtkSetMacro(Columns, int);
  vtkGetMacro(Columns, int);
  ///@}

  ///@{
  /**
   * Side length of a square lot, in metres (> 0). Default 30 m.
   */
  vtkSetMacro(Spacing, double);
  vtkGetMacro(Spacing, double);
  ///@}

  ///@{
  /**
   * Range of a building footprint's side as a fraction of Spacing, drawn independently
   * along x and y. Must satisfy 0 < FootprintMin <= FootprintMax <= 1 (1 lets neighbouring
   * buildings touch). Defaults 0.4 and 0.8 (dimensionless).
   */
  vtkSetMacro(FootprintMin, double);
  vtkGetMacro(FootprintMin, double);
  vtkSetMacro(FootprintMax, double);
  vtkGetMacro(FootprintMax, double);
  ///@}

  ///@{
  /**
   * Range of building heights above the ground, in metres: each building's highest point
   * (roof, or ridge of a gable roof) is uniform in [MinHeight, MaxHeight).
   * Must satisfy 0 < MinHeight <= MaxHeight. Defaults 8 m and 40 m.
   */
  vtkSetMacro(MinHeight, double);
  vtkGetMacro(MinHeight, double);
  vtkSetMacro(MaxHeight, double);
  vtkGetMacro(MaxHeight, double);
  ///@}

  ///@{
  /**
   * Probability that a building gets a gable roof instead of a flat one, in [0, 1].
   * Default 0.25 (dimensionless). The ridge runs along the longer footprint side.
   */
  vtkSetMacro(GableRoofFraction, double);
  vtkGetMacro(GableRoofFraction, double);
  ///@}

  ///@{
  /**
   * Pitch of gable roofs, in degrees, in (0, 90). Default 30 degrees. The roof rise is
   * limited to half the building height, so a steep roof on a low, wide building becomes
   * flatter rather than turning the building into a tent.
   */
  vtkSetMacro(GableRoofPitch, double);
  vtkGetMacro(GableRoofPitch, double);
  ///@}

  ///@{
  /**
   * Seed of the std::mt19937 generator that draws footprints, positions, heights and roof
   * types (any value; negative seeds are used modulo 2^32). Default 1. Equal seeds (and
   * parameters) give bit-identical output.
   */
  vtkSetMacro(Seed, int);
  vtkGetMacro(Seed, int);
  ///@}

  ///@{
  /**
   * Whether to add a ground plane (PartId 0) under the block. Default on.
   */
  vtkSetMacro(GenerateGround, vtkTypeBool);
  vtkGetMacro(GenerateGround, vtkTypeBool);
  vtkBooleanMacro(GenerateGround, vtkTypeBool);
  ///@}

  ///@{
  /**
   * How far the ground extends beyond the lots on every side, in metres (>= 0).
   * Default 20 m. The ground is split into quads of at most about one lot, so per-vertex
   * attributes and shadow receivers stay well sampled.
   */
  vtkSetMacro(GroundMargin, double);
  vtkGetMacro(GroundMargin, double);
  ///@}

  ///@{
  /**
   * Translation of the whole block, in metres: the lower-left corner of lot (0, 0) at
   * ground level. Default (0, 0, 0). Georeferenced values such as (3.45e6, 5.43e6, 0) are
   * fine: geometry is built around zero and offset in double precision.
   */
  vtkSetVector3Macro(Origin, double);
  vtkGetVector3Macro(Origin, double);
  ///@}

protected:
  vtkPenumbraCityBlockSource();
  ~vtkPenumbraCityBlockSource() override = default;

  int RequestData(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;

  int Rows;
  int Columns;
  double Spacing;
  double FootprintMin;
  double FootprintMax;
  double MinHeight;
  double MaxHeight;
  double GableRoofFraction;
  double GableRoofPitch;
  int Seed;
  vtkTypeBool GenerateGround;
  double GroundMargin;
  double Origin[3];

private:
  vtkPenumbraCityBlockSource(const vtkPenumbraCityBlockSource&) = delete;
  void operator=(const vtkPenumbraCityBlockSource&) = delete;

  bool CheckParameters();
};

#endif
