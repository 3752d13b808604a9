#include "vtkPenumbraSceneGeometryInternals.h"

#include "vtkAssemblyPath.h"
#include "vtkCamera.h"
#include "vtkInformation.h"
#include "vtkInformationStringKey.h"
#include "vtkObjectFactory.h"
#include "vtkRenderer.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkPenumbraSceneGeometry);
vtkInformationKeyMacro(vtkPenumbraSceneGeometry, NAME, String);

vtkPenumbraSceneGeometry::DisplayAttributesAccessor
  vtkPenumbraSceneGeometry::Internals::DisplayAttributes = nullptr;

namespace
{
using penumbra_scene::PathKey;
using penumbra_scene::PropEntry;
using penumbra_scene::TriangleList;
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
    layout.emplace_back(e->Path, e->Triangles.Size());
    propFlags.push_back(e->Flags);
  }
  if (layout != this->PublishedLayout)
  {
    geometryChanged = true;
  }

  this->Offsets.assign(this->Props.size(), 0);
  this->IndexOfLeaf.clear();
  vtkIdType total = 0;
  double before[6];
  std::copy(this->Bounds, this->Bounds + 6, before);
  vtkMath::UninitializeBounds(this->Bounds);
  bool first = true;
  auto grow = [&](const double* b)
  {
    if (vtkMath::AreBoundsInitialized(b))
    {
      for (int c = 0; c < 3; ++c)
      {
        this->Bounds[2 * c] = first ? b[2 * c] : std::min(this->Bounds[2 * c], b[2 * c]);
        this->Bounds[2 * c + 1] =
          first ? b[2 * c + 1] : std::max(this->Bounds[2 * c + 1], b[2 * c + 1]);
      }
      first = false;
    }
  };
  for (size_t p = 0; p < this->Props.size(); ++p)
  {
    PropEntry& e = *this->Props[p];
    this->Offsets[p] = total;
    total += e.Triangles.Size();
    this->IndexOfLeaf.emplace(e.Leaf.GetPointer(), static_cast<int>(p));
    grow(e.Bounds);
  }
  if (total > 0)
  {
    grow(this->SceneBounds);
  }
  // The epsilons and scales of the techniques follow the bounds (SetSceneBounds() alone may
  // move them).
  geometryChanged = geometryChanged || !std::equal(before, before + 6, this->Bounds);

  const double previous[3] = { origin[0], origin[1], origin[2] };
  this->ChooseOrigin(origin);
  if (previous[0] != origin[0] || previous[1] != origin[1] || previous[2] != origin[2])
  {
    geometryChanged = true;
  }

  const bool flagsChanged = geometryChanged || propFlags != this->PublishedPropFlags;
  std::vector<penumbra::SceneTriangles::Block> blocks;
  blocks.reserve(this->Props.size());
  this->Degenerate = 0;
  for (size_t p = 0; p < this->Props.size(); ++p)
  {
    PropEntry& e = *this->Props[p];
    TriangleList& tl = e.Triangles;
    // The float32 positions follow the points and the origin; a prop whose triangles and the
    // origin are unchanged keeps them.
    if (tl.Rebased.size() != tl.Points.size() + 1 || !std::equal(origin, origin + 3, e.RebasedFor))
    {
      tl.Rebase(origin);
      std::copy(origin, origin + 3, e.RebasedFor);
    }
    blocks.push_back({ this->Offsets[p], &tl, e.Flags });
    this->Degenerate += tl.Degenerate;
  }
  this->Triangles.Reset(origin, std::move(blocks));
  if (geometryChanged)
  {
    this->GeometryTime.Modified();
  }
  if (flagsChanged)
  {
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
  this->Triangles.Reset(this->Triangles.GetOrigin(), {});
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
}

//------------------------------------------------------------------------------
vtkPenumbraSceneGeometry::~vtkPenumbraSceneGeometry() = default;

//------------------------------------------------------------------------------
double vtkPenumbraSceneGeometry::ComputePixelSize(vtkCamera* camera, int width, int height)
{
  if (!camera || width <= 0 || height <= 0)
  {
    return 0.0;
  }
  if (camera->GetParallelProjection())
  {
    return 2.0 * camera->GetParallelScale() / height;
  }
  const double halfAngle = vtkMath::RadiansFromDegrees(0.5 * camera->GetViewAngle());
  const int pixels = camera->GetUseHorizontalViewAngle() ? width : height;
  return 2.0 * camera->GetDistance() * std::tan(halfAngle) / pixels;
}

//------------------------------------------------------------------------------
int vtkPenumbraSceneGeometry::Update(vtkRenderer* renderer)
{
  std::vector<vtkProp*> props;
  if (renderer)
  {
    int width = 0, height = 0;
    if (renderer->GetRenderWindow() && renderer->IsActiveCameraCreated())
    {
      renderer->GetTiledSize(&width, &height);
      const double size =
        vtkPenumbraSceneGeometry::ComputePixelSize(renderer->GetActiveCamera(), width, height);
      if (size > 0.0 && std::isfinite(size))
      {
        this->PixelSize = size;
      }
    }
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
  impl.Notes.clear();
  impl.PixelSize = this->PixelSize;
  for (auto& texture : impl.Textures)
  {
    texture.second.Used = false;
  }

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
      if (!impl.VisitPath(i, path, previous, error))
      {
        break;
      }
    }
  }
  // Textures no prop uses any more are forgotten.
  for (auto it = impl.Textures.begin(); it != impl.Textures.end();)
  {
    it = it->second.Used ? std::next(it) : impl.Textures.erase(it);
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
  Internals::DisplayAttributes = accessor;
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
  auto casts = [](const PropEntry* e, vtkIdType t)
  { return (e->Triangles.Roles[static_cast<size_t>(t)] & e->Flags & CASTS_SHADOWS) != 0; };
  vtkIdType count = 0;
  for (const PropEntry* e : this->Impl->Props)
  {
    for (vtkIdType t = 0; t < e->Triangles.Size(); ++t)
    {
      count += casts(e, t) ? 1 : 0;
    }
  }
  world->SetNumberOfComponents(9);
  world->SetNumberOfTuples(count);
  double* out = world->GetPointer(0);
  for (const PropEntry* e : this->Impl->Props)
  {
    for (vtkIdType t = 0; t < e->Triangles.Size(); ++t)
    {
      if (casts(e, t))
      {
        for (int k = 0; k < 3; ++k)
        {
          const double* w = e->Triangles.Point(t, k);
          out = std::copy(w, w + 3, out);
        }
      }
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
  return this->Impl->Triangles.Size();
}

//------------------------------------------------------------------------------
const penumbra::SceneTriangles& vtkPenumbraSceneGeometry::GetTriangles()
{
  return this->Impl->Triangles;
}

//------------------------------------------------------------------------------
bool vtkPenumbraSceneGeometry::GetTriangle(vtkIdType t, double vertices[9])
{
  if (t < 0 || t >= this->GetNumberOfTriangles())
  {
    std::fill(vertices, vertices + 9, 0.0);
    return false;
  }
  this->Impl->Triangles.Get(t, vertices);
  return true;
}

//------------------------------------------------------------------------------
int vtkPenumbraSceneGeometry::GetTriangleFlags(vtkIdType t)
{
  return t >= 0 && t < this->GetNumberOfTriangles() ? this->Impl->Triangles.GetFlags(t) : 0;
}

//------------------------------------------------------------------------------
vtkIdType vtkPenumbraSceneGeometry::GetTriangleOwner(vtkIdType t)
{
  return t >= 0 && t < this->GetNumberOfTriangles() ? this->Impl->Triangles.GetOwner(t) : -1;
}

//------------------------------------------------------------------------------
vtkIdType vtkPenumbraSceneGeometry::GetTriangleCellId(vtkIdType t)
{
  return t >= 0 && t < this->GetNumberOfTriangles() ? this->Impl->Triangles.GetCellId(t) : -1;
}

//------------------------------------------------------------------------------
int vtkPenumbraSceneGeometry::GetTrianglePropIndex(vtkIdType t)
{
  return t >= 0 && t < this->GetNumberOfTriangles() ? this->Impl->Triangles.GetPropIndex(t) : -1;
}

//------------------------------------------------------------------------------
size_t vtkPenumbraSceneGeometry::GetTriangleBytes()
{
  size_t bytes = 0;
  for (const PropEntry* e : this->Impl->Props)
  {
    bytes += e->Triangles.HeapBytes();
  }
  return bytes;
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
  return this->Impl->Props[index]->Triangles.Size();
}

//------------------------------------------------------------------------------
int vtkPenumbraSceneGeometry::GetPropIndex(vtkProp* prop)
{
  auto it = this->Impl->IndexOfLeaf.find(prop);
  return it == this->Impl->IndexOfLeaf.end() ? -1 : it->second;
}

//------------------------------------------------------------------------------
int vtkPenumbraSceneGeometry::GetNumberOfCastingNotes()
{
  return static_cast<int>(this->Impl->Notes.size());
}

//------------------------------------------------------------------------------
vtkProp* vtkPenumbraSceneGeometry::GetCastingNoteProp(int index)
{
  return index >= 0 && index < this->GetNumberOfCastingNotes()
    ? this->Impl->Notes[static_cast<size_t>(index)].first.GetPointer()
    : nullptr;
}

//------------------------------------------------------------------------------
const char* vtkPenumbraSceneGeometry::GetCastingNote(int index)
{
  return index >= 0 && index < this->GetNumberOfCastingNotes()
    ? this->Impl->Notes[static_cast<size_t>(index)].second.c_str()
    : nullptr;
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
  // The prop's caster-only triangles follow its drawn ones: no primitive maps to them.
  if (propIndex < 0 || propIndex >= this->GetNumberOfProps() || primitiveId < 0)
  {
    return -1;
  }
  const PropEntry& e = *this->Impl->Props[propIndex];
  if (!e.Mappable || !e.Surface)
  {
    return -1;
  }
  const penumbra_scene::PrimitiveCounts& c = e.Counts;
  const vtkIdType offset = this->Impl->Offsets[propIndex];
  const vtkIdType trisStart = c.VertPrimitives + c.LinePrimitives;
  if (primitiveId < trisStart)
  {
    return -1; // a point or line primitive
  }
  const vtkIdType q = primitiveId - trisStart;
  if (q < c.DrawnPolyTriangles)
  {
    return offset + (c.DrawnPolyToLocal.empty() ? q : c.DrawnPolyToLocal[q]);
  }
  const vtkIdType stripsStart =
    trisStart + (e.ExactCellMap ? c.DrawnPolyTriangles : c.PolyConservative);
  const vtkIdType s = primitiveId - stripsStart;
  if (s < 0 || s >= c.StripTriangles)
  {
    return -1;
  }
  return offset + c.PolyTriangles + s;
}

//------------------------------------------------------------------------------
vtkIdType vtkPenumbraSceneGeometry::GetFirstSurfacePrimitive(int propIndex)
{
  if (propIndex < 0 || propIndex >= this->GetNumberOfProps())
  {
    return -1;
  }
  const PropEntry& e = *this->Impl->Props[propIndex];
  switch (e.What)
  {
    case penumbra_scene::Kind::Image:
      return 0;
    case penumbra_scene::Kind::Splats:
      return VTK_ID_MAX;
    case penumbra_scene::Kind::Unsupported:
      return -1;
    default:
      break;
  }
  if (!e.Surface)
  {
    return VTK_ID_MAX; // wireframe and points representations draw lines and points only
  }
  if (e.Mappable)
  {
    return e.Counts.VertPrimitives + e.Counts.LinePrimitives;
  }
  return e.PointsOrLines ? -1 : 0;
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
vtkMTimeType vtkPenumbraSceneGeometry::GetCastersTime()
{
  return std::max(this->GetGeometryTime(), this->GetFlagsTime());
}

//------------------------------------------------------------------------------
int vtkPenumbraSceneGeometry::GetNumberOfPropsExtractedLastUpdate()
{
  return this->Impl->ExtractedLastUpdate;
}

//------------------------------------------------------------------------------
bool vtkPenumbraSceneGeometry::IsOccluder(vtkIdType index)
{
  return index >= 0 && index < this->GetNumberOfTriangles() &&
    this->Impl->Triangles.IsOccluder(index);
}

//------------------------------------------------------------------------------
vtkIdType vtkPenumbraSceneGeometry::GetNumberOfDegenerateTriangles()
{
  return this->Impl->Degenerate;
}

//------------------------------------------------------------------------------
void vtkPenumbraSceneGeometry::SetSceneBounds(const double bounds[6])
{
  double b[6];
  vtkMath::UninitializeBounds(b);
  if (bounds && vtkMath::AreBoundsInitialized(bounds))
  {
    std::copy(bounds, bounds + 6, b);
  }
  if (!std::equal(b, b + 6, this->Impl->SceneBounds))
  {
    std::copy(b, b + 6, this->Impl->SceneBounds);
    this->Modified();
  }
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
  os << indent << "PixelSize: " << this->PixelSize << "\n";
  os << indent << "NumberOfCastingNotes: " << this->GetNumberOfCastingNotes() << "\n";
  os << indent << "NumberOfPropsExtractedLastUpdate: " << this->Impl->ExtractedLastUpdate << "\n";
  os << indent << "GeometryTime: " << this->GetGeometryTime() << "\n";
  os << indent << "FlagsTime: " << this->GetFlagsTime() << "\n";
  os << indent << "CastersTime: " << this->GetCastersTime() << "\n";
  os << indent << "ErrorMessage: " << this->Impl->ErrorMessage << "\n";
}
