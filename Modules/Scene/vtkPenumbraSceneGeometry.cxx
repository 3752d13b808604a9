#include "vtkPenumbraSceneGeometry.h"

#include "vtkPenumbraShadowKeys.h"

#include "vtkAbstractArray.h"
#include "vtkActor.h"
#include "vtkAssemblyNode.h"
#include "vtkAssemblyPath.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCompositeDataDisplayAttributes.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataObjectTree.h"
#include "vtkDataObjectTreeIterator.h"
#include "vtkDataSet.h"
#include "vtkDataSetMapper.h"
#include "vtkDataSetSurfaceFilter.h"
#include "vtkDoubleArray.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationStringKey.h"
#include "vtkIntArray.h"
#include "vtkMapper.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkProp.h"
#include "vtkPropCollection.h"
#include "vtkProperty.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

namespace
{
vtkPenumbraSceneGeometry::DisplayAttributesAccessor DisplayAttributes = nullptr;
}

vtkStandardNewMacro(vtkPenumbraSceneGeometry);
vtkInformationKeyMacro(vtkPenumbraSceneGeometry, NAME, String);

namespace
{
// Everything kept about one extracted prop (an actor, or one assembly path to a part actor).
// Triangles are stored in absolute world coordinates so that the global arrays can be rebuilt
// for a new Origin without re-extracting.
struct PropEntry
{
  // Identity: the props of the assembly path, root first (a single prop for a plain actor).
  std::vector<vtkProp*> Path;
  vtkSmartPointer<vtkProp> Leaf;
  std::vector<vtkSmartPointer<vtkProp>> PathRefs; // keep the path's props alive with the key

  // What the extraction depended on; all unchanged means the triangles are still right.
  vtkSmartPointer<vtkMapper> Mapper;
  vtkSmartPointer<vtkDataObject> Data;
  vtkMTimeType DataMTime = 0;
  vtkMTimeType MapperMTime = 0;
  double Matrix[16];
  vtkSmartPointer<vtkCompositeDataDisplayAttributes> Attributes; // block visibilities, if any
  vtkMTimeType AttributesMTime = 0;

  std::vector<double> World;      // 9 per triangle, absolute world coordinates
  std::vector<vtkIdType> CellIds; // per triangle
  vtkIdType Degenerate = 0;
  double Bounds[6];

  // VTK 9.1 primitive numbering of the polydata the mapper draws (see MapPrimitiveId).
  bool Mappable = false;          // false for composite inputs
  vtkIdType VertPrimitives = 0;   // verts: one point primitive per point id
  vtkIdType LinePrimitives = 0;   // lines: one segment per consecutive point pair
  vtkIdType PolyTriangles = 0;    // our fan triangles of polygons (all of them)
  vtkIdType PolyConservative = 0; // connectivity - 2 * cells: VTK's map-less estimate
  vtkIdType StripTriangles = 0;
  std::vector<vtkIdType> DrawnPolyToLocal; // only when VTK skips some fan triangles
  vtkIdType DrawnPolyTriangles = 0;
  vtkSmartPointer<vtkPolyData> Drawn; // the single polydata drawn, to re-check colouring

  // Re-evaluated by every Update (cheap, and not part of the geometry).
  unsigned char Flags = 0;
  bool Surface = true;
  bool ExactCellMap = false;
  bool GeometryChanged = false; // by the current Update
};

using PathKey = std::vector<vtkProp*>;

void TransformPoint(const double m[16], const double p[3], double out[3])
{
  const double w = m[12] * p[0] + m[13] * p[1] + m[14] * p[2] + m[15];
  for (int r = 0; r < 3; ++r)
  {
    out[r] = m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3];
  }
  // Affine matrices (the usual case) have w == 1 exactly; dividing then changes nothing.
  if (w != 1.0)
  {
    out[0] /= w;
    out[1] /= w;
    out[2] /= w;
  }
}

bool IsFinite3(const double p[3])
{
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

// Zero area up to rounding: the sine of the largest angle between two edges is below 1e-12.
bool IsDegenerate(const double* a, const double* b, const double* c)
{
  double e1[3], e2[3], e3[3], n[3];
  for (int k = 0; k < 3; ++k)
  {
    e1[k] = b[k] - a[k];
    e2[k] = c[k] - a[k];
    e3[k] = c[k] - b[k];
  }
  vtkMath::Cross(e1, e2, n);
  const double l1 = vtkMath::Dot(e1, e1), l2 = vtkMath::Dot(e2, e2), l3 = vtkMath::Dot(e3, e3);
  const double longest = std::max(l1, std::max(l2, l3));
  return longest == 0.0 || vtkMath::Norm(n) <= 1e-12 * longest;
}

bool SamePoint(vtkPoints* pts, vtkIdType a, vtkIdType b)
{
  if (a == b)
  {
    return true;
  }
  double pa[3], pb[3];
  pts->GetPoint(a, pa);
  pts->GetPoint(b, pb);
  return pa[0] == pb[0] && pa[1] == pb[1] && pa[2] == pb[2];
}

std::string PropLabel(vtkProp* leaf, int propNumber, const std::vector<vtkProp*>& path)
{
  std::ostringstream s;
  const char* name = vtkPenumbraSceneGeometry::GetPropName(leaf);
  if (!name && !path.empty())
  {
    name = vtkPenumbraSceneGeometry::GetPropName(path.front());
  }
  if (name)
  {
    s << leaf->GetClassName() << " '" << name << "'";
  }
  else
  {
    s << "unnamed " << leaf->GetClassName();
  }
  s << " (prop " << propNumber;
  if (path.size() > 1)
  {
    s << ", assembly part at depth " << path.size() - 1;
  }
  s << ")";
  return s.str();
}

// HaveCellScalars || HaveCellNormals as vtkOpenGLPolyDataMapper::BuildBufferObjects (VTK 9.1)
// decides them: only then does the mapper build its full vtkOpenGLCellToVTKCellMap, whose
// strip offset differs from the map-less estimate when polygons contain skipped triangles.
bool UsesExactCellMap(vtkMapper* mapper, vtkActor* actor, vtkPolyData* poly)
{
  bool cellScalars = false;
  if (mapper->GetScalarVisibility() &&
    mapper->GetScalarMode() != VTK_SCALAR_MODE_USE_POINT_FIELD_DATA)
  {
    int cellFlag = 0;
    vtkAbstractArray* scalars = vtkAbstractMapper::GetAbstractScalars(poly, mapper->GetScalarMode(),
      mapper->GetArrayAccessMode(), mapper->GetArrayId(), mapper->GetArrayName(), cellFlag);
    cellScalars = scalars && scalars->GetNumberOfTuples() > 0 && cellFlag != 0;
  }
  vtkDataArray* pointNormals = actor->GetProperty()->GetInterpolation() != VTK_FLAT
    ? poly->GetPointData()->GetNormals()
    : nullptr;
  const bool cellNormals = !pointNormals && poly->GetCellData()->GetNormals();
  return cellScalars || cellNormals;
}
} // namespace

struct vtkPenumbraSceneGeometry::Internals
{
  std::string ErrorMessage;
  vtkNew<vtkDoubleArray> Vertices;
  vtkNew<vtkIntArray> PropIndices;
  vtkNew<vtkIdTypeArray> CellIds;
  vtkNew<vtkUnsignedCharArray> Flags;

  std::map<PathKey, PropEntry> Cache; // every prop seen by the last Update, visible or not
  std::vector<PropEntry*> Props;      // the extracted list, in order
  std::vector<vtkIdType> Offsets;     // first global triangle of each prop
  std::unordered_map<vtkProp*, int> IndexOfLeaf;

  vtkTimeStamp GeometryTime;
  vtkTimeStamp FlagsTime;
  int ExtractedLastUpdate = 0;
  vtkIdType Degenerate = 0;
  double Bounds[6];

  bool HaveOrigin = false;
  double OriginExtent = 0.0; // the extent the current Origin was chosen for

  // Signature of the last published content, to tell real changes from no-ops.
  std::vector<std::pair<PathKey, vtkIdType>> PublishedLayout;
  std::vector<unsigned char> PublishedPropFlags;

  vtkNew<vtkDataSetSurfaceFilter> Surface;
  vtkSmartPointer<vtkPropCollection> ShadowOnly;

  Internals() { vtkMath::UninitializeBounds(this->Bounds); }

  // Extracts one polydata's triangles (polygons fanned, then strips, as VTK draws them).
  // Returns the number of points with non-finite world coordinates used by triangles.
  vtkIdType AppendPolyData(
    vtkPolyData* poly, const double m[16], vtkIdType cellIdBase, PropEntry& e, bool track);

  // Appends the visible polydata leaves below `block` (depth first), advancing cellBase
  // past hidden ones too; returns the number of NaN/inf points met.
  vtkIdType AppendBlocks(
    vtkDataObject* block, bool parentVisible, PropEntry& e, vtkIdType& cellBase);
  // Re-extracts an entry from its mapper's input. Returns false with `message` on bad input.
  bool Extract(PropEntry& e, const std::string& label, std::string& message);

  void ChooseOrigin(double origin[3]);
  void Publish(double origin[3], bool geometryChanged);
  void Clear();
};

//------------------------------------------------------------------------------
vtkIdType vtkPenumbraSceneGeometry::Internals::AppendPolyData(
  vtkPolyData* poly, const double m[16], vtkIdType cellIdBase, PropEntry& e, bool track)
{
  vtkPoints* pts = poly->GetPoints();
  vtkCellArray* polys = poly->GetPolys();
  vtkCellArray* strips = poly->GetStrips();
  const vtkIdType nVerts = poly->GetVerts()->GetNumberOfCells();
  const vtkIdType nLines = poly->GetLines()->GetNumberOfCells();
  const vtkIdType nPolys = polys->GetNumberOfCells();

  if (track)
  {
    // VTK 9.1 vtkOpenGLCellToVTKCellMap::BuildPrimitiveOffsetsIfNeeded (surface
    // representation): verts count one primitive per connectivity id, lines one per
    // connectivity id minus one per cell.
    vtkCellArray* verts = poly->GetVerts();
    vtkCellArray* lines = poly->GetLines();
    e.VertPrimitives = verts->GetNumberOfConnectivityIds();
    e.LinePrimitives = lines->GetNumberOfConnectivityIds() - lines->GetNumberOfCells();
    e.PolyConservative = polys->GetNumberOfConnectivityIds() - 2 * nPolys;
  }
  if (!pts || pts->GetNumberOfPoints() == 0 || (nPolys == 0 && strips->GetNumberOfCells() == 0))
  {
    return 0;
  }

  // Transform every point once; the triangles then copy them.
  const vtkIdType nPts = pts->GetNumberOfPoints();
  std::vector<double> world(3 * static_cast<size_t>(nPts));
  std::vector<char> bad(static_cast<size_t>(nPts), 0);
  for (vtkIdType i = 0; i < nPts; ++i)
  {
    double p[3];
    pts->GetPoint(i, p);
    TransformPoint(m, p, &world[3 * i]);
    bad[i] = IsFinite3(&world[3 * i]) ? 0 : 1;
  }
  std::set<vtkIdType> badUsed;

  auto emit = [&](vtkIdType a, vtkIdType b, vtkIdType c, vtkIdType cellId)
  {
    for (vtkIdType id : { a, b, c })
    {
      if (bad[id])
      {
        badUsed.insert(id);
      }
      const double* w = &world[3 * id];
      e.World.insert(e.World.end(), w, w + 3);
    }
    e.CellIds.push_back(cellId);
    if (IsDegenerate(&world[3 * a], &world[3 * b], &world[3 * c]))
    {
      ++e.Degenerate;
    }
  };

  // Polygons: fan (p0, p_i, p_i+1), as vtkOpenGLIndexBufferObject::AppendTriangleIndexBuffer.
  // That function leaves out fan triangles with two coincident points (equal coordinates in
  // the points' own precision); we keep them but record which GL primitive is which.
  const vtkIdType polyBase = static_cast<vtkIdType>(e.CellIds.size());
  std::vector<vtkIdType> skipped;
  vtkIdType npts = 0;
  const vtkIdType* ids = nullptr;
  vtkIdType cell = 0;
  for (polys->InitTraversal(); polys->GetNextCell(npts, ids); ++cell)
  {
    for (vtkIdType i = 1; i + 1 < npts; ++i)
    {
      if (track &&
        (SamePoint(pts, ids[0], ids[i]) || SamePoint(pts, ids[0], ids[i + 1]) ||
          SamePoint(pts, ids[i], ids[i + 1])))
      {
        skipped.push_back(static_cast<vtkIdType>(e.CellIds.size()) - polyBase);
      }
      emit(ids[0], ids[i], ids[i + 1], cellIdBase + nVerts + nLines + cell);
    }
  }
  const vtkIdType polyTriangles = static_cast<vtkIdType>(e.CellIds.size()) - polyBase;

  // Strips: triangle j is (p_j, p_j+1+j%2, p_j+1+(j+1)%2), keeping a consistent winding,
  // as vtkOpenGLIndexBufferObject::AppendStripIndexBuffer (surface); none are skipped.
  const vtkIdType stripBase = static_cast<vtkIdType>(e.CellIds.size());
  cell = 0;
  for (strips->InitTraversal(); strips->GetNextCell(npts, ids); ++cell)
  {
    for (vtkIdType j = 0; j + 2 < npts; ++j)
    {
      emit(ids[j], ids[j + 1 + j % 2], ids[j + 1 + (j + 1) % 2],
        cellIdBase + nVerts + nLines + nPolys + cell);
    }
  }

  if (track)
  {
    e.PolyTriangles = polyTriangles;
    e.StripTriangles = static_cast<vtkIdType>(e.CellIds.size()) - stripBase;
    e.DrawnPolyTriangles = polyTriangles - static_cast<vtkIdType>(skipped.size());
    e.DrawnPolyToLocal.clear();
    if (!skipped.empty())
    {
      e.DrawnPolyToLocal.reserve(static_cast<size_t>(e.DrawnPolyTriangles));
      size_t s = 0;
      for (vtkIdType t = 0; t < polyTriangles; ++t)
      {
        if (s < skipped.size() && skipped[s] == t)
        {
          ++s;
          continue;
        }
        e.DrawnPolyToLocal.push_back(t);
      }
    }
  }
  return static_cast<vtkIdType>(badUsed.size());
}

//------------------------------------------------------------------------------
bool vtkPenumbraSceneGeometry::Internals::Extract(
  PropEntry& e, const std::string& label, std::string& message)
{
  e.World.clear();
  e.CellIds.clear();
  e.Degenerate = 0;
  e.Mappable = false;
  e.VertPrimitives = e.LinePrimitives = e.PolyTriangles = e.PolyConservative = 0;
  e.StripTriangles = e.DrawnPolyTriangles = 0;
  e.DrawnPolyToLocal.clear();
  e.Drawn = nullptr;

  for (double v : e.Matrix)
  {
    if (!std::isfinite(v))
    {
      message = label + ": the prop matrix has NaN/inf entries";
      return false;
    }
  }

  vtkIdType badPoints = 0;
  vtkDataObject* data = e.Data;
  if (auto* composite = vtkCompositeDataSet::SafeDownCast(data))
  {
    // Composite inputs are drawn by vtkCompositePolyDataMapper2, which draws only the visible
    // polydata leaves. Cell ids continue from block to block in depth-first order, counting
    // every polydata leaf, hidden ones included.
    vtkIdType cellBase = 0;
    badPoints = this->AppendBlocks(composite, true, e, cellBase);
  }
  else if (auto* poly = vtkPolyData::SafeDownCast(data))
  {
    badPoints = this->AppendPolyData(poly, e.Matrix, 0, e, true);
    e.Mappable = true;
    e.Drawn = poly;
  }
  else if (auto* dataSet = vtkDataSet::SafeDownCast(data))
  {
    // vtkDataSetMapper draws the output of a default vtkDataSetSurfaceFilter: running the same
    // filter gives the same cells in the same order.
    this->Surface->SetInputData(dataSet);
    this->Surface->Update();
    vtkNew<vtkPolyData> surface;
    surface->ShallowCopy(this->Surface->GetOutput());
    this->Surface->SetInputData(nullptr);
    badPoints = this->AppendPolyData(surface, e.Matrix, 0, e, true);
    e.Mappable = true;
    e.Drawn = surface;
  }

  if (badPoints > 0)
  {
    message = label + ": " + std::to_string(badPoints) + (badPoints == 1 ? " point" : " points") +
      " with NaN/inf coordinates";
    e.World.clear();
    e.CellIds.clear();
    return false;
  }

  vtkMath::UninitializeBounds(e.Bounds);
  if (!e.World.empty())
  {
    e.Bounds[0] = e.Bounds[2] = e.Bounds[4] = VTK_DOUBLE_MAX;
    e.Bounds[1] = e.Bounds[3] = e.Bounds[5] = VTK_DOUBLE_MIN;
    for (size_t i = 0; i < e.World.size(); i += 3)
    {
      for (int c = 0; c < 3; ++c)
      {
        e.Bounds[2 * c] = std::min(e.Bounds[2 * c], e.World[i + c]);
        e.Bounds[2 * c + 1] = std::max(e.Bounds[2 * c + 1], e.World[i + c]);
      }
    }
  }
  return true;
}

//------------------------------------------------------------------------------
vtkIdType vtkPenumbraSceneGeometry::Internals::AppendBlocks(
  vtkDataObject* block, bool parentVisible, PropEntry& e, vtkIdType& cellBase)
{
  // A block's own visibility if set, else its parent's (vtkCompositePolyDataMapper2's rule).
  vtkCompositeDataDisplayAttributes* attributes = e.Attributes;
  const bool visible = attributes && attributes->HasBlockVisibility(block)
    ? attributes->GetBlockVisibility(block)
    : parentVisible;
  vtkIdType badPoints = 0;
  if (auto* poly = vtkPolyData::SafeDownCast(block))
  {
    if (visible)
    {
      badPoints += this->AppendPolyData(poly, e.Matrix, cellBase, e, false);
    }
    cellBase += poly->GetNumberOfCells();
  }
  else if (auto* tree = vtkDataObjectTree::SafeDownCast(block))
  {
    vtkSmartPointer<vtkDataObjectTreeIterator> it;
    it.TakeReference(tree->NewTreeIterator());
    it->TraverseSubTreeOff();
    it->VisitOnlyLeavesOff();
    it->SkipEmptyNodesOn();
    for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem())
    {
      badPoints += this->AppendBlocks(it->GetCurrentDataObject(), visible, e, cellBase);
    }
  }
  return badPoints;
}

//------------------------------------------------------------------------------
void vtkPenumbraSceneGeometry::Internals::ChooseOrigin(double origin[3])
{
  if (!vtkMath::AreBoundsInitialized(this->Bounds))
  {
    return; // no triangles: keep the previous origin rather than jump to (0, 0, 0)
  }
  double centre[3], extent = 0.0;
  for (int c = 0; c < 3; ++c)
  {
    centre[c] = 0.5 * (this->Bounds[2 * c] + this->Bounds[2 * c + 1]);
    extent = std::max(extent, this->Bounds[2 * c + 1] - this->Bounds[2 * c]);
  }
  // Keep the current origin while it is still a good one: the scene's centre stays within
  // one extent of it and the extent changed by less than a factor of 4 since it was chosen.
  // One prop moving (or a few appearing) then never moves the origin, so float32 positions
  // of the other props stay bit-identical from frame to frame.
  const double e = std::max(extent, 1.0);
  const double eRef = std::max(this->OriginExtent, 1.0);
  if (this->HaveOrigin && e <= 4.0 * eRef && e >= 0.25 * eRef)
  {
    bool near = true;
    for (int c = 0; c < 3; ++c)
    {
      near = near && std::fabs(centre[c] - origin[c]) <= e;
    }
    if (near)
    {
      return;
    }
  }
  // A multiple of a power of two (at least 1 m, about 1/16 of the extent) is exact in double,
  // short in print, and makes (vertex - origin) exact for vertices near it (Sterbenz).
  const double quantum = std::exp2(std::ceil(std::log2(std::max(extent / 16.0, 1.0))));
  for (int c = 0; c < 3; ++c)
  {
    origin[c] = std::round(centre[c] / quantum) * quantum;
  }
  this->HaveOrigin = true;
  this->OriginExtent = extent;
}

//------------------------------------------------------------------------------
void vtkPenumbraSceneGeometry::Internals::Publish(double origin[3], bool geometryChanged)
{
  // Layout = which entries, in which order, with how many triangles.
  std::vector<std::pair<PathKey, vtkIdType>> layout;
  std::vector<unsigned char> propFlags;
  layout.reserve(this->Props.size());
  for (PropEntry* e : this->Props)
  {
    layout.emplace_back(e->Path, static_cast<vtkIdType>(e->CellIds.size()));
    propFlags.push_back(e->Flags);
  }
  if (layout != this->PublishedLayout)
  {
    geometryChanged = true;
  }

  this->Offsets.assign(this->Props.size(), 0);
  this->IndexOfLeaf.clear();
  vtkIdType total = 0;
  vtkMath::UninitializeBounds(this->Bounds);
  bool first = true;
  for (size_t p = 0; p < this->Props.size(); ++p)
  {
    PropEntry& e = *this->Props[p];
    this->Offsets[p] = total;
    total += static_cast<vtkIdType>(e.CellIds.size());
    this->IndexOfLeaf.emplace(e.Leaf.GetPointer(), static_cast<int>(p));
    if (vtkMath::AreBoundsInitialized(e.Bounds))
    {
      for (int c = 0; c < 3; ++c)
      {
        this->Bounds[2 * c] =
          first ? e.Bounds[2 * c] : std::min(this->Bounds[2 * c], e.Bounds[2 * c]);
        this->Bounds[2 * c + 1] =
          first ? e.Bounds[2 * c + 1] : std::max(this->Bounds[2 * c + 1], e.Bounds[2 * c + 1]);
      }
      first = false;
    }
  }

  const double previous[3] = { origin[0], origin[1], origin[2] };
  this->ChooseOrigin(origin);
  if (previous[0] != origin[0] || previous[1] != origin[1] || previous[2] != origin[2])
  {
    geometryChanged = true;
  }

  const bool flagsChanged = geometryChanged || propFlags != this->PublishedPropFlags;
  if (geometryChanged)
  {
    this->Vertices->SetNumberOfTuples(total);
    this->PropIndices->SetNumberOfTuples(total);
    this->CellIds->SetNumberOfTuples(total);
    double* v = this->Vertices->GetPointer(0);
    this->Degenerate = 0;
    for (size_t p = 0; p < this->Props.size(); ++p)
    {
      PropEntry& e = *this->Props[p];
      const vtkIdType offset = this->Offsets[p];
      const vtkIdType n = static_cast<vtkIdType>(e.CellIds.size());
      for (vtkIdType t = 0; t < n; ++t)
      {
        for (int k = 0; k < 9; ++k)
        {
          v[9 * (offset + t) + k] = e.World[9 * t + k] - origin[k % 3];
        }
        this->PropIndices->SetValue(offset + t, static_cast<int>(p));
        this->CellIds->SetValue(offset + t, e.CellIds[t]);
      }
      this->Degenerate += e.Degenerate;
    }
    this->Vertices->Modified();
    this->GeometryTime.Modified();
  }
  if (flagsChanged)
  {
    this->Flags->SetNumberOfTuples(total);
    for (size_t p = 0; p < this->Props.size(); ++p)
    {
      const vtkIdType offset = this->Offsets[p];
      const vtkIdType n = static_cast<vtkIdType>(this->Props[p]->CellIds.size());
      for (vtkIdType t = 0; t < n; ++t)
      {
        this->Flags->SetValue(offset + t, this->Props[p]->Flags);
      }
    }
    this->Flags->Modified();
    this->FlagsTime.Modified();
  }
  this->PublishedLayout.swap(layout);
  this->PublishedPropFlags.swap(propFlags);
}

//------------------------------------------------------------------------------
void vtkPenumbraSceneGeometry::Internals::Clear()
{
  const bool hadContent = !this->PublishedLayout.empty();
  this->Props.clear();
  this->Offsets.clear();
  this->IndexOfLeaf.clear();
  this->PublishedLayout.clear();
  this->PublishedPropFlags.clear();
  this->Vertices->SetNumberOfTuples(0);
  this->PropIndices->SetNumberOfTuples(0);
  this->CellIds->SetNumberOfTuples(0);
  this->Flags->SetNumberOfTuples(0);
  this->Degenerate = 0;
  vtkMath::UninitializeBounds(this->Bounds);
  if (hadContent)
  {
    this->GeometryTime.Modified();
    this->FlagsTime.Modified();
  }
}

//------------------------------------------------------------------------------
vtkPenumbraSceneGeometry::vtkPenumbraSceneGeometry()
  : Impl(new Internals)
{
  this->Origin[0] = this->Origin[1] = this->Origin[2] = 0.0;
  this->Impl->Vertices->SetName("Vertices");
  this->Impl->Vertices->SetNumberOfComponents(9);
  this->Impl->PropIndices->SetName("PropIndices");
  this->Impl->CellIds->SetName("CellIds");
  this->Impl->Flags->SetName("Flags");
}

//------------------------------------------------------------------------------
vtkPenumbraSceneGeometry::~vtkPenumbraSceneGeometry() = default;

//------------------------------------------------------------------------------
int vtkPenumbraSceneGeometry::Update(vtkRenderer* renderer)
{
  std::vector<vtkProp*> props;
  if (renderer)
  {
    vtkPropCollection* collection = renderer->GetViewProps();
    vtkCollectionSimpleIterator it;
    collection->InitTraversal(it);
    while (vtkProp* prop = collection->GetNextProp(it))
    {
      props.push_back(prop);
    }
  }
  if (vtkPropCollection* extra = this->Impl->ShadowOnly)
  {
    vtkCollectionSimpleIterator it;
    extra->InitTraversal(it);
    while (vtkProp* prop = extra->GetNextProp(it))
    {
      props.push_back(prop);
    }
  }
  return this->Update(props.empty() ? nullptr : props.data(), static_cast<int>(props.size()));
}

//------------------------------------------------------------------------------
int vtkPenumbraSceneGeometry::Update(vtkProp** props, int count)
{
  Internals& impl = *this->Impl;
  impl.ErrorMessage.clear();
  impl.ExtractedLastUpdate = 0;
  impl.Props.clear();

  std::map<PathKey, PropEntry> previous;
  previous.swap(impl.Cache);
  std::string error;

  for (int i = 0; i < count && error.empty(); ++i)
  {
    vtkProp* prop = props ? props[i] : nullptr;
    if (!prop)
    {
      continue;
    }
    prop->InitPathTraversal();
    while (vtkAssemblyPath* path = prop->GetNextPath())
    {
      PathKey key;
      bool visible = true, casts = true, receives = true;
      vtkCollectionSimpleIterator pit;
      path->InitTraversal(pit);
      while (vtkAssemblyNode* node = path->GetNextNode(pit))
      {
        vtkProp* p = node->GetViewProp();
        key.push_back(p);
        visible = visible && p->GetVisibility();
        // A flag set on an assembly applies to all its parts.
        casts = casts && vtkPenumbraShadowKeys::CastsShadows(p);
        receives = receives && vtkPenumbraShadowKeys::ReceivesShadows(p);
      }
      auto* actor = vtkActor::SafeDownCast(path->GetLastNode()->GetViewProp());
      if (!actor)
      {
        continue; // volumes, 2D actors, images: no surface triangles
      }

      // Keep the entry of an invisible prop (unchanged) so that showing it again is free.
      auto found = previous.find(key);
      if (!visible)
      {
        if (found != previous.end())
        {
          impl.Cache.emplace(key, std::move(found->second));
          previous.erase(found);
        }
        continue;
      }

      vtkMapper* mapper = actor->GetMapper();
      if (!mapper || mapper->GetNumberOfInputConnections(0) < 1)
      {
        continue;
      }
      // Bring the input up to date the way the mapper's render would (Static: not at all).
      if (!mapper->GetStatic())
      {
        mapper->Update();
      }
      vtkDataObject* data = mapper->GetInputDataObject(0, 0);
      if (!data)
      {
        continue;
      }

      // The world matrix: a plain actor's own, an assembly part's concatenated path matrix.
      double matrix[16];
      vtkMatrix4x4* m = key.size() > 1 ? path->GetLastNode()->GetMatrix() : actor->GetMatrix();
      if (m)
      {
        vtkMatrix4x4::DeepCopy(matrix, m);
      }
      else
      {
        vtkMatrix4x4::Identity(matrix);
      }

      vtkCompositeDataDisplayAttributes* attributes =
        DisplayAttributes && vtkCompositeDataSet::SafeDownCast(data) ? DisplayAttributes(mapper)
                                                                     : nullptr;
      PropEntry entry;
      bool reuse = false;
      if (found != previous.end())
      {
        PropEntry& old = found->second;
        reuse = old.Mapper == mapper && old.Data == data && old.DataMTime == data->GetMTime() &&
          old.Attributes == attributes &&
          old.AttributesMTime == (attributes ? attributes->GetMTime() : 0) &&
          old.MapperMTime == mapper->GetMTime() && std::equal(matrix, matrix + 16, old.Matrix);
        entry = std::move(old);
        previous.erase(found);
      }
      if (!reuse)
      {
        const std::vector<double> oldWorld = std::move(entry.World);
        const std::vector<vtkIdType> oldCells = std::move(entry.CellIds);
        entry.Path = key;
        entry.Leaf = actor;
        entry.PathRefs.assign(key.begin(), key.end());
        entry.Mapper = mapper;
        entry.Data = data;
        entry.DataMTime = data->GetMTime();
        entry.MapperMTime = mapper->GetMTime();
        entry.Attributes = attributes;
        entry.AttributesMTime = attributes ? attributes->GetMTime() : 0;
        std::copy(matrix, matrix + 16, entry.Matrix);
        ++impl.ExtractedLastUpdate;
        if (!impl.Extract(entry, PropLabel(actor, i, key), error))
        {
          break; // not cached: the next Update looks at it again
        }
        entry.GeometryChanged = entry.World != oldWorld || entry.CellIds != oldCells;
      }
      else
      {
        entry.GeometryChanged = false;
      }

      entry.Flags =
        static_cast<unsigned char>((casts ? CASTS_SHADOWS : 0) | (receives ? RECEIVES_SHADOWS : 0));
      entry.Surface = actor->GetProperty()->GetRepresentation() == VTK_SURFACE;
      // Only a prop with both skipped fan triangles and strips depends on the cell map.
      entry.ExactCellMap = entry.Mappable && entry.Drawn && entry.StripTriangles > 0 &&
        entry.DrawnPolyTriangles != entry.PolyConservative &&
        UsesExactCellMap(mapper, actor, entry.Drawn);

      auto inserted = impl.Cache.emplace(key, std::move(entry));
      if (inserted.second)
      {
        impl.Props.push_back(&inserted.first->second);
      }
    }
  }

  if (!error.empty())
  {
    impl.ErrorMessage = error;
    impl.Clear();
    vtkErrorMacro(<< error);
    return 0;
  }

  bool geometryChanged = false;
  for (PropEntry* e : impl.Props)
  {
    geometryChanged = geometryChanged || e->GeometryChanged;
  }
  impl.Publish(this->Origin, geometryChanged);
  return 1;
}

//------------------------------------------------------------------------------
void vtkPenumbraSceneGeometry::SetDisplayAttributesAccessor(DisplayAttributesAccessor accessor)
{
  DisplayAttributes = accessor;
}

//------------------------------------------------------------------------------
void vtkPenumbraSceneGeometry::SetShadowOnlyProps(vtkPropCollection* props)
{
  if (props != this->Impl->ShadowOnly)
  {
    this->Impl->ShadowOnly = props;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
vtkPropCollection* vtkPenumbraSceneGeometry::GetShadowOnlyProps()
{
  return this->Impl->ShadowOnly;
}

//------------------------------------------------------------------------------
void vtkPenumbraSceneGeometry::GetCasterWorldTriangles(vtkDoubleArray* world)
{
  vtkIdType count = 0;
  for (const PropEntry* e : this->Impl->Props)
  {
    count += (e->Flags & CASTS_SHADOWS) ? static_cast<vtkIdType>(e->CellIds.size()) : 0;
  }
  world->SetNumberOfComponents(9);
  world->SetNumberOfTuples(count);
  double* out = world->GetPointer(0);
  for (const PropEntry* e : this->Impl->Props)
  {
    if (e->Flags & CASTS_SHADOWS)
    {
      out = std::copy(e->World.begin(), e->World.end(), out);
    }
  }
  world->Modified();
}

//------------------------------------------------------------------------------
const char* vtkPenumbraSceneGeometry::GetErrorMessage()
{
  return this->Impl->ErrorMessage.c_str();
}

//------------------------------------------------------------------------------
vtkIdType vtkPenumbraSceneGeometry::GetNumberOfTriangles()
{
  return this->Impl->Vertices->GetNumberOfTuples();
}

//------------------------------------------------------------------------------
vtkDoubleArray* vtkPenumbraSceneGeometry::GetVertices()
{
  return this->Impl->Vertices;
}

//------------------------------------------------------------------------------
vtkIntArray* vtkPenumbraSceneGeometry::GetPropIndices()
{
  return this->Impl->PropIndices;
}

//------------------------------------------------------------------------------
vtkIdTypeArray* vtkPenumbraSceneGeometry::GetCellIds()
{
  return this->Impl->CellIds;
}

//------------------------------------------------------------------------------
vtkUnsignedCharArray* vtkPenumbraSceneGeometry::GetFlags()
{
  return this->Impl->Flags;
}

//------------------------------------------------------------------------------
int vtkPenumbraSceneGeometry::GetNumberOfProps()
{
  return static_cast<int>(this->Impl->Props.size());
}

//------------------------------------------------------------------------------
vtkProp* vtkPenumbraSceneGeometry::GetProp(int index)
{
  if (index < 0 || index >= this->GetNumberOfProps())
  {
    return nullptr;
  }
  return this->Impl->Props[index]->Leaf;
}

//------------------------------------------------------------------------------
vtkIdType vtkPenumbraSceneGeometry::GetPropTriangleOffset(int index)
{
  if (index < 0 || index >= this->GetNumberOfProps())
  {
    return -1;
  }
  return this->Impl->Offsets[index];
}

//------------------------------------------------------------------------------
vtkIdType vtkPenumbraSceneGeometry::GetPropTriangleCount(int index)
{
  if (index < 0 || index >= this->GetNumberOfProps())
  {
    return 0;
  }
  return static_cast<vtkIdType>(this->Impl->Props[index]->CellIds.size());
}

//------------------------------------------------------------------------------
int vtkPenumbraSceneGeometry::GetPropIndex(vtkProp* prop)
{
  auto it = this->Impl->IndexOfLeaf.find(prop);
  return it == this->Impl->IndexOfLeaf.end() ? -1 : it->second;
}

//------------------------------------------------------------------------------
vtkIdType vtkPenumbraSceneGeometry::MapPrimitiveId(int propIndex, vtkIdType primitiveId)
{
  // Mirrors VTK 9.1 vtkOpenGLPolyDataMapper (surface representation):
  // - RenderPieceStart sets PrimitiveIDOffset = 0; RenderPieceDraw draws the cell BOs in the
  //   order points (verts), lines, tris (polys), tri strips, and after drawing BO i (< 3) sets
  //   PrimitiveIDOffset = CellCellMap->GetPrimitiveOffsets()[i + 1]; SetMapperShaderParameters
  //   passes it as the "PrimitiveIDOffset" uniform.
  // - vtkOpenGLCellToVTKCellMap::BuildPrimitiveOffsetsIfNeeded: offsets[1] = #vert point ids,
  //   offsets[2] = offsets[1] + (line point ids - line cells), offsets[3] = offsets[2] +
  //   (poly point ids - 2 * poly cells); when the mapper has cell scalars or cell normals,
  //   BuildCellSupportArrays counts instead only the fan triangles it draws.
  // - vtkOpenGLIndexBufferObject::AppendTriangleIndexBuffer fans each polygon (0, i, i+1) and
  //   leaves out fan triangles with two coincident points; AppendStripIndexBuffer emits
  //   every strip triangle.
  if (propIndex < 0 || propIndex >= this->GetNumberOfProps() || primitiveId < 0)
  {
    return -1;
  }
  const PropEntry& e = *this->Impl->Props[propIndex];
  if (!e.Mappable || !e.Surface)
  {
    return -1;
  }
  const vtkIdType offset = this->Impl->Offsets[propIndex];
  const vtkIdType trisStart = e.VertPrimitives + e.LinePrimitives;
  if (primitiveId < trisStart)
  {
    return -1; // a point or line primitive
  }
  const vtkIdType q = primitiveId - trisStart;
  if (q < e.DrawnPolyTriangles)
  {
    return offset + (e.DrawnPolyToLocal.empty() ? q : e.DrawnPolyToLocal[q]);
  }
  const vtkIdType stripsStart =
    trisStart + (e.ExactCellMap ? e.DrawnPolyTriangles : e.PolyConservative);
  const vtkIdType s = primitiveId - stripsStart;
  if (s < 0 || s >= e.StripTriangles)
  {
    return -1;
  }
  return offset + e.PolyTriangles + s;
}

//------------------------------------------------------------------------------
vtkMTimeType vtkPenumbraSceneGeometry::GetGeometryTime()
{
  return this->Impl->GeometryTime.GetMTime();
}

//------------------------------------------------------------------------------
vtkMTimeType vtkPenumbraSceneGeometry::GetFlagsTime()
{
  return this->Impl->FlagsTime.GetMTime();
}

//------------------------------------------------------------------------------
int vtkPenumbraSceneGeometry::GetNumberOfPropsExtractedLastUpdate()
{
  return this->Impl->ExtractedLastUpdate;
}

//------------------------------------------------------------------------------
bool vtkPenumbraSceneGeometry::IsOccluder(vtkIdType index)
{
  if (index < 0 || index >= this->GetNumberOfTriangles() ||
    !(this->GetFlags()->GetValue(index) & CASTS_SHADOWS))
  {
    return false;
  }
  const double* p = this->GetVertices()->GetPointer(9 * index);
  const double e1[3] = { p[3] - p[0], p[4] - p[1], p[5] - p[2] };
  const double e2[3] = { p[6] - p[0], p[7] - p[1], p[8] - p[2] };
  double cross[3];
  vtkMath::Cross(e1, e2, cross);
  const double a2 = vtkMath::Dot(cross, cross);
  return a2 > 0.0 && std::isfinite(a2);
}

//------------------------------------------------------------------------------
vtkIdType vtkPenumbraSceneGeometry::GetNumberOfDegenerateTriangles()
{
  return this->Impl->Degenerate;
}

//------------------------------------------------------------------------------
void vtkPenumbraSceneGeometry::GetBounds(double bounds[6])
{
  std::copy(this->Impl->Bounds, this->Impl->Bounds + 6, bounds);
}

//------------------------------------------------------------------------------
void vtkPenumbraSceneGeometry::SetPropName(vtkProp* prop, const char* name)
{
  if (!prop)
  {
    return;
  }
  if (!prop->GetPropertyKeys())
  {
    vtkNew<vtkInformation> keys;
    prop->SetPropertyKeys(keys);
  }
  if (name)
  {
    prop->GetPropertyKeys()->Set(NAME(), name);
  }
  else
  {
    prop->GetPropertyKeys()->Remove(NAME());
  }
}

//------------------------------------------------------------------------------
const char* vtkPenumbraSceneGeometry::GetPropName(vtkProp* prop)
{
  vtkInformation* keys = prop ? prop->GetPropertyKeys() : nullptr;
  return keys && keys->Has(NAME()) ? keys->Get(NAME()) : nullptr;
}

//------------------------------------------------------------------------------
void vtkPenumbraSceneGeometry::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Origin: (" << this->Origin[0] << ", " << this->Origin[1] << ", "
     << this->Origin[2] << ")\n";
  os << indent << "NumberOfProps: " << this->GetNumberOfProps() << "\n";
  os << indent << "NumberOfTriangles: " << this->GetNumberOfTriangles() << "\n";
  os << indent << "NumberOfDegenerateTriangles: " << this->Impl->Degenerate << "\n";
  os << indent << "NumberOfPropsExtractedLastUpdate: " << this->Impl->ExtractedLastUpdate << "\n";
  os << indent << "GeometryTime: " << this->GetGeometryTime() << "\n";
  os << indent << "FlagsTime: " << this->GetFlagsTime() << "\n";
  os << indent << "ErrorMessage: " << this->Impl->ErrorMessage << "\n";
}
