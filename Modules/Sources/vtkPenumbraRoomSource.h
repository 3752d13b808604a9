/**
 * @class   vtkPenumbraRoomSource
 * @brief   Closed furnished room whose walls face inward: a test scene for point-light shadows.
 *
 * The room shell is the box x in [-Size[0]/2, Size[0]/2], y in [-Size[1]/2, Size[1]/2],
 * z in [0, Size[2]] (floor at z = 0). Its six faces are subdivided into quads of at most
 * ShellCellSize and their normals point into the room, so the shell is lit from inside and
 * back-face culling shows the interior.
 *
 * The furniture is laid out so that a point light at the room centre (0, 0, Size[2]/2)
 * casts a shadow onto every one of the six room faces, while leaving part of each face lit:
 *
 *  - PartId 1: a table (slab on four legs) off-centre: shadows on the floor;
 *  - PartId 2: a cabinet in front of the +x wall;
 *  - PartId 3: a floor-to-ceiling column toward the -x wall (also shadows floor and ceiling);
 *  - PartId 4: a low shelf in front of the +y wall;
 *  - PartId 5: a wardrobe in front of the -y wall;
 *  - PartId 6: a lamp-shade ring hanging above the centre: a ring of shadow on the ceiling.
 *
 * The shell has PartId 0 (int cell array "PartId"). The layout is designed for the default
 * 10 x 10 x 4 m room and scaled with Size (the shade keeps a circular shape, scaled with the
 * smaller horizontal factor), which preserves which face each object shadows.
 * Furniture faces have outward normals. Output is triangles with point normals; points are
 * double precision.
 *
 * Invalid parameters make RequestData report an error and leave the output empty.
 */

#ifndef vtkPenumbraRoomSource_h
#define vtkPenumbraRoomSource_h

#include "vtkPenumbraSourcesModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

class VTKPENUMBRASOURCES_EXPORT vtkPenumbraRoomSource : public vtkPolyDataAlgorithm
{
public:
  static vtkPenumbraRoomSource* New();
  vtkTypeMacro(vtkPenumbraRoomSource, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Inner size of the room along x, y and z, in metres; each finite and > 0.
   * Default (10, 10, 4) m.
   */
  vtkSetVector3Macro(Size, double);
  vtkGetVector3Macro(Size, double);
  ///@}

  ///@{
  /**
   * Largest edge of the quads the shell faces are split into, in metres (finite, > 0;
   * at most 1024 quads per edge are made). Default 0.5 m. Finer shells give smoother
   * per-vertex attributes and more samples for shadow tests.
   */
  vtkSetMacro(ShellCellSize, double);
  vtkGetMacro(ShellCellSize, double);
  ///@}

  ///@{
  /**
   * Whether to generate the furniture (PartId > 0). Default on; off leaves the empty shell.
   */
  vtkSetMacro(GenerateFurniture, vtkTypeBool);
  vtkGetMacro(GenerateFurniture, vtkTypeBool);
  vtkBooleanMacro(GenerateFurniture, vtkTypeBool);
  ///@}

  /**
   * Where the layout expects the point light: the room centre (0, 0, Size[2]/2), in metres.
   */
  void GetLightPosition(double position[3]);

protected:
  vtkPenumbraRoomSource();
  ~vtkPenumbraRoomSource() override = default;

  int RequestData(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;

  double Size[3];
  double ShellCellSize;
  vtkTypeBool GenerateFurniture;

private:
  vtkPenumbraRoomSource(const vtkPenumbraRoomSource&) = delete;
  void operator=(const vtkPenumbraRoomSource&) = delete;
};

#endif
