/**
 * @class   vtkPenumbraMeshFileCheck
 * @brief   Checks an untrusted mesh file before a VTK reader sees it.
 *
 * Some of VTK 9.1's readers trust the file they read. `vtkPLYReader` asserts or frees a bad
 * pointer (the process aborts with `free(): invalid pointer`) on a binary PLY cut short after
 * its header, reads past the words of a short ASCII line, and passes face indices on unchecked;
 * `vtkOBJReader` accepts a face that indexes a vertex the file does not have, which renders
 * garbage or crashes later. This class walks the file's structure (not its geometry) and
 * reports the first problem as one sentence, so the scene reader can refuse the file before
 * VTK reads it:
 *
 *  - PLY (ascii, binary_little_endian, binary_big_endian): the header grammar (Turk's PLY
 *    format, as implemented by VTK's vtkPLY), element counts and property types; every
 *    record and list present in the file, i.e. for binary files the header's counts times the
 *    record sizes fit the file; list lengths not negative; face indices inside the vertex
 *    count; ASCII records one per line with enough values and no longer than the 4094
 *    characters VTK's line buffer holds.
 *  - OBJ: every `f`, `l` and `p` index (absolute or negative/relative) names an existing
 *    vertex, texture coordinate or normal; numbers parse.
 *  - Legacy VTK (.vtk) POLYDATA and UNSTRUCTURED_GRID, ASCII or BINARY: the POINTS are all
 *    there, and every cell block (VERTICES, LINES, POLYGONS, TRIANGLE_STRIPS, CELLS; the
 *    classic count-and-ids layout or version 5's OFFSETS/CONNECTIVITY) has the cells and
 *    the size its header declares, with point ids inside the points: VTK 9.1's
 *    vtkCellArray::ImportLegacyFormat trusts the per-cell counts and reads past the array
 *    otherwise. Unknown keywords are refused. POINT_DATA and CELL_DATA must match the points
 *    and cells, and every attribute and FIELD array header (components, tuples) must fit
 *    in the file: vtkDataReader allocates what a header declares before reading a value.
 *  - Other formats: no structural check here; the scene reader still checks the connectivity
 *    of what any reader returns (vtkPenumbraMeshFileCheck::CheckConnectivity).
 *
 * The check reads the file once; its cost is that of reading the file.
 */

#ifndef vtkPenumbraMeshFileCheck_h
#define vtkPenumbraMeshFileCheck_h

#include "vtkObject.h"
#include "vtkPenumbraSceneModule.h" // For export macro

#include <string> // For the error message

class vtkDataSet;

class VTKPENUMBRASCENE_EXPORT vtkPenumbraMeshFileCheck : public vtkObject
{
public:
  static vtkPenumbraMeshFileCheck* New();
  vtkTypeMacro(vtkPenumbraMeshFileCheck, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The file to check. Default: none. The format comes from the extension (.ply, .obj, .vtk;
   * other extensions pass unchecked).
   */
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  /**
   * Checks FileName. Returns 1 if a VTK reader may read it, 0 otherwise; then
   * GetErrorMessage() says what is wrong (without the file name), e.g.
   * `binary PLY ends after 12 of 1000 "vertex" records (header promises 12000 bytes, 144
   * follow the header)`. Reports nothing through vtkErrorMacro: the caller decides.
   */
  int Check();

  /**
   * The problem found by the last Check(), empty after a success.
   */
  const char* GetErrorMessage() { return this->ErrorMessage.c_str(); }

  /**
   * Checks what a reader produced: every cell's point ids lie in [0, number of points), and
   * in a vtkUnstructuredGrid every cell has a type (linear or quadratic, not polyhedron or
   * higher order) with the number of points that type needs. Returns an empty string or the
   * problem, e.g. `polygon 7 uses point 120 but there are only 100 points`. Other data sets
   * are built without explicit ids and always pass.
   */
  static std::string CheckConnectivity(vtkDataSet* data);

protected:
  vtkPenumbraMeshFileCheck();
  ~vtkPenumbraMeshFileCheck() override;

  char* FileName;
  std::string ErrorMessage;

private:
  vtkPenumbraMeshFileCheck(const vtkPenumbraMeshFileCheck&) = delete;
  void operator=(const vtkPenumbraMeshFileCheck&) = delete;
};

#endif
