#include "vtkPenumbraMeshFileCheck.h"
#include "vtkPenumbraMeshFileCheckInternals.h"

#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkCellType.h"
#include "vtkObjectFactory.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"
#include "vtksys/SystemTools.hxx"

using namespace penumbra_mesh_check;

namespace
{
// Point count a fixed-size VTK cell type needs (vtkCellType.h); 0 for a variable count
// (at least `minimum`), -1 for a type the surface filter cannot take apart safely.
int CellTypePoints(int type, int& minimum)
{
  minimum = 0;
  switch (type)
  {
    case VTK_EMPTY_CELL:
      return 0;
    case VTK_VERTEX:
      return 1;
    case VTK_POLY_VERTEX:
      minimum = 1;
      return 0;
    case VTK_LINE:
      return 2;
    case VTK_POLY_LINE:
      minimum = 2;
      return 0;
    case VTK_TRIANGLE:
      return 3;
    case VTK_TRIANGLE_STRIP:
      minimum = 3;
      return 0;
    case VTK_POLYGON:
      minimum = 3;
      return 0;
    case VTK_PIXEL:
      return 4;
    case VTK_QUAD:
      return 4;
    case VTK_TETRA:
      return 4;
    case VTK_VOXEL:
      return 8;
    case VTK_HEXAHEDRON:
      return 8;
    case VTK_WEDGE:
      return 6;
    case VTK_PYRAMID:
      return 5;
    case VTK_PENTAGONAL_PRISM:
      return 10;
    case VTK_HEXAGONAL_PRISM:
      return 12;
    case VTK_QUADRATIC_EDGE:
      return 3;
    case VTK_QUADRATIC_TRIANGLE:
      return 6;
    case VTK_QUADRATIC_QUAD:
      return 8;
    case VTK_QUADRATIC_TETRA:
      return 10;
    case VTK_QUADRATIC_HEXAHEDRON:
      return 20;
    case VTK_QUADRATIC_WEDGE:
      return 15;
    case VTK_QUADRATIC_PYRAMID:
      return 13;
    case VTK_BIQUADRATIC_QUAD:
      return 9;
    case VTK_TRIQUADRATIC_HEXAHEDRON:
      return 27;
    case VTK_QUADRATIC_LINEAR_QUAD:
      return 6;
    case VTK_QUADRATIC_LINEAR_WEDGE:
      return 12;
    case VTK_BIQUADRATIC_QUADRATIC_WEDGE:
      return 18;
    case VTK_BIQUADRATIC_QUADRATIC_HEXAHEDRON:
      return 24;
    case VTK_BIQUADRATIC_TRIANGLE:
      return 7;
    case VTK_CUBIC_LINE:
      return 4;
    default:
      return -1;
  }
}

// A cell type that needs more points than the cell has makes vtkDataSetSurfaceFilter read
// past the cell's ids.
std::string CheckCellTypes(vtkUnstructuredGrid* grid)
{
  const vtkIdType cells = grid->GetNumberOfCells();
  vtkUnsignedCharArray* types = grid->GetCellTypesArray();
  if (cells > 0 && (!types || types->GetNumberOfValues() != cells))
  {
    return std::to_string(cells) + " cells but " +
      std::to_string(types ? types->GetNumberOfValues() : 0) + " cell types";
  }
  for (vtkIdType c = 0; c < cells; ++c)
  {
    const int type = types->GetValue(c);
    const vtkIdType n = grid->GetCells()->GetCellSize(c);
    int minimum = 0;
    const int needed = CellTypePoints(type, minimum);
    if (needed < 0)
    {
      return "cell " + std::to_string(c) + " has the unsupported cell type " + std::to_string(type);
    }
    if ((needed > 0 && n != needed) || (needed == 0 && n < minimum))
    {
      return "cell " + std::to_string(c) + " of type " + std::to_string(type) + " has " +
        std::to_string(n) + " points, the type needs " +
        std::to_string(needed > 0 ? needed : minimum) + (needed > 0 ? "" : " or more");
    }
  }
  return std::string();
}

std::string CheckCells(vtkCellArray* cells, vtkIdType points, const char* kind)
{
  if (!cells)
  {
    return std::string();
  }
  auto it = vtk::TakeSmartPointer(cells->NewIterator());
  vtkIdType n = 0;
  const vtkIdType* ids = nullptr;
  for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell())
  {
    it->GetCurrentCell(n, ids);
    for (vtkIdType k = 0; k < n; ++k)
    {
      if (ids[k] < 0 || ids[k] >= points)
      {
        return std::string(kind) + " " + std::to_string(it->GetCurrentCellId()) + " uses point " +
          std::to_string(ids[k]) + " but there are only " + std::to_string(points) + " points";
      }
    }
  }
  return std::string();
}
}

vtkStandardNewMacro(vtkPenumbraMeshFileCheck);

vtkPenumbraMeshFileCheck::vtkPenumbraMeshFileCheck()
  : FileName(nullptr)
{
}

vtkPenumbraMeshFileCheck::~vtkPenumbraMeshFileCheck()
{
  this->SetFileName(nullptr);
}

int vtkPenumbraMeshFileCheck::Check()
{
  this->ErrorMessage.clear();
  if (!this->FileName || !*this->FileName)
  {
    this->ErrorMessage = "no file name given";
    return 0;
  }
  const std::string path = this->FileName;
  const std::string ext =
    vtksys::SystemTools::LowerCase(vtksys::SystemTools::GetFilenameLastExtension(path));
  try
  {
    if (ext == ".ply")
    {
      CheckPly(path);
    }
    else if (ext == ".obj")
    {
      CheckObj(path);
    }
    else if (ext == ".vtk")
    {
      CheckLegacy(path);
    }
  }
  catch (const FileProblem& e)
  {
    this->ErrorMessage = e.what();
  }
  catch (const std::exception& e)
  {
    this->ErrorMessage = std::string("cannot be checked: ") + e.what();
  }
  return this->ErrorMessage.empty() ? 1 : 0;
}

std::string vtkPenumbraMeshFileCheck::CheckConnectivity(vtkDataSet* data)
{
  if (auto* pd = vtkPolyData::SafeDownCast(data))
  {
    const vtkIdType n = pd->GetNumberOfPoints();
    std::string why = CheckCells(pd->GetVerts(), n, "vertex cell");
    why = why.empty() ? CheckCells(pd->GetLines(), n, "line") : why;
    why = why.empty() ? CheckCells(pd->GetPolys(), n, "polygon") : why;
    why = why.empty() ? CheckCells(pd->GetStrips(), n, "triangle strip") : why;
    return why;
  }
  if (auto* ug = vtkUnstructuredGrid::SafeDownCast(data))
  {
    const std::string why = CheckCells(ug->GetCells(), ug->GetNumberOfPoints(), "cell");
    return why.empty() ? CheckCellTypes(ug) : why;
  }
  return std::string();
}

void vtkPenumbraMeshFileCheck::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "ErrorMessage: " << this->ErrorMessage << "\n";
}
