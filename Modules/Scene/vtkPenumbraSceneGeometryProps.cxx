#include "vtkPenumbraSceneGeometryInternals.h"

#include "vtkPenumbraSceneInstances.h"
#include "vtkPenumbraShadowKeys.h"

#include "vtkAbstractArray.h"
#include "vtkActor.h"
#include "vtkAssemblyNode.h"
#include "vtkAssemblyPath.h"
#include "vtkCellData.h"
#include "vtkCompositeDataDisplayAttributes.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataObjectTree.h"
#include "vtkDataObjectTreeIterator.h"
#include "vtkDataSet.h"
#include "vtkDataSetSurfaceFilter.h"
#include "vtkGlyph3DMapper.h"
#include "vtkImageData.h"
#include "vtkImageMapper3D.h"
#include "vtkImageProperty.h"
#include "vtkImageSlice.h"
#include "vtkMapper.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkPlane.h"
#include "vtkPlaneCollection.h"
#include "vtkPointData.h"
#include "vtkPointGaussianMapper.h"
#include "vtkPolyData.h"
#include "vtkProp.h"
#include "vtkProp3D.h"
#include "vtkPropCollection.h"
#include "vtkProperty.h"
#include "vtkScalarsToColors.h"
#include "vtkSkybox.h"
#include "vtkSmartPointer.h"
#include "vtkTexture.h"
#include "vtkTransform.h"
#include "vtkVolume.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace
{
using penumbra_scene::DrawStyle;
using penumbra_scene::Kind;
using penumbra_scene::Outcome;
using penumbra_scene::PathKey;
using penumbra_scene::PropEntry;
using penumbra_scene::Settings;
using penumbra_scene::TextureAlpha;
using penumbra_scene::TriangleList;

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

// The kind of shape `mapper` draws. Polydata mappers that draw impostors (spheres, sticks)
// are not reproduced.
Kind KindOf(vtkAbstractMapper* mapper)
{
  if (vtkGlyph3DMapper::SafeDownCast(mapper))
  {
    return Kind::Glyphs;
  }
  if (vtkPointGaussianMapper::SafeDownCast(mapper))
  {
    return Kind::Splats;
  }
  if (mapper->IsA("vtkOpenGLSphereMapper") || mapper->IsA("vtkOpenGLStickMapper"))
  {
    return Kind::Unsupported;
  }
  if (mapper->IsA("vtkPolyDataMapper") || mapper->IsA("vtkCompositePolyDataMapper") ||
    mapper->IsA("vtkDataSetMapper"))
  {
    return Kind::Polygonal;
  }
  return Kind::Unsupported;
}

// The first six clipping planes of a mapper (VTK's limit) as kept half-spaces, world.
void ClipPlanes(vtkAbstractMapper* mapper, Settings& s)
{
  vtkPlaneCollection* planes = mapper->GetClippingPlanes();
  const int count = planes ? std::min(planes->GetNumberOfItems(), 6) : 0;
  for (int i = 0; i < count; ++i)
  {
    vtkPlane* plane = planes->GetItem(i);
    double n[3], o[3];
    plane->GetNormal(n);
    plane->GetOrigin(o);
    const penumbra_scene::Plane half = { n[0], n[1], n[2], -vtkMath::Dot(n, o) };
    s.Style.Clip.push_back(half);
    s.Key.insert(s.Key.end(), half.begin(), half.end());
  }
  s.Key.push_back(count);
}

bool Finite16(const double m[16])
{
  return std::all_of(m, m + 16, [](double v) { return std::isfinite(v); });
}

// The mapper's input, brought up to date the way its render would (`update` false for a
// Static mapper); null without mapper or input.
vtkDataObject* UpdatedInput(vtkAbstractMapper* mapper, bool update)
{
  if (!mapper || mapper->GetNumberOfInputConnections(0) < 1)
  {
    return nullptr;
  }
  if (update)
  {
    mapper->Update();
  }
  return mapper->GetInputDataObject(0, 0);
}

// Whether world widths are the same for casting: an orbit about the focal point recomputes
// the camera distance, and with it the pixel size, to within a few ulps; a millionth of the
// width is no visible change, a zoom or resize is.
bool SameWidths(const double a[3], const double b[3])
{
  for (int k = 0; k < 3; ++k)
  {
    if (!(std::fabs(a[k] - b[k]) <= 1e-6 * std::max(std::fabs(a[k]), std::fabs(b[k]))))
    {
      return false;
    }
  }
  return true;
}

// An entry for `leaf` drawn by `mapper` from `data` with `matrix`, before extraction.
PropEntry Candidate(const PathKey& key, vtkProp* leaf, vtkAbstractMapper* mapper,
  vtkDataObject* data, const double matrix[16])
{
  PropEntry candidate;
  candidate.Path = key;
  candidate.Leaf = leaf;
  candidate.Mapper = mapper;
  candidate.Data = data;
  candidate.DataMTime = data->GetMTime();
  candidate.MapperMTime = mapper->GetMTime();
  std::copy(matrix, matrix + 16, candidate.Matrix);
  return candidate;
}
} // namespace

//------------------------------------------------------------------------------
const TextureAlpha& vtkPenumbraSceneGeometry::Internals::TextureAlphaOf(vtkTexture* texture)
{
  // The texture's input is brought up to date first, as its render would; the alpha is read
  // again only when the texture, its image or its table changed.
  if (texture->GetNumberOfInputConnections(0) > 0)
  {
    texture->GetInputAlgorithm()->Update();
  }
  vtkImageData* image = texture->GetInput();
  vtkScalarsToColors* lut = texture->GetLookupTable();
  const std::vector<double> key = { static_cast<double>(texture->GetMTime()),
    static_cast<double>(image ? image->GetMTime() : 0),
    static_cast<double>(lut ? lut->GetMTime() : 0) };
  TextureAlpha& cached = this->Textures[texture];
  cached.Used = true;
  if (cached.Texture != texture || cached.Key != key)
  {
    cached.Texture = texture;
    cached.Key = key;
    cached.Why.clear();
    cached.Ok = cached.Grid.Build(texture, cached.Why);
  }
  return cached;
}

//------------------------------------------------------------------------------
void vtkPenumbraSceneGeometry::Internals::Note(
  vtkProp* prop, const std::string& label, const std::string& note)
{
  this->Notes.emplace_back(prop, label + ": " + note);
}

//------------------------------------------------------------------------------
Settings vtkPenumbraSceneGeometry::Internals::ActorSettings(vtkActor* actor, vtkMapper* mapper)
{
  Settings s;
  vtkProperty* property = actor->GetProperty();
  DrawStyle& style = s.Style;
  style.Representation = property->GetRepresentation();
  style.EdgeVisibility = property->GetEdgeVisibility() != 0;
  style.VertexVisibility = property->GetVertexVisibility();
  // Widths in pixels (VTK draws edges at least 1.1 pixels wide) times a pixel's world size.
  const double lineWidth = property->GetLineWidth();
  const double pointSize = property->GetPointSize();
  style.LineWidth = lineWidth * this->PixelSize;
  style.PointSize = pointSize * this->PixelSize;
  style.EdgeWidth = std::max(lineWidth, 1.1) * this->PixelSize;
  s.Invisible = property->GetOpacity() == 0.0;
  s.Key = { static_cast<double>(style.Representation), style.EdgeVisibility ? 1.0 : 0.0,
    style.VertexVisibility ? 1.0 : 0.0, lineWidth, pointSize, s.Invisible ? 1.0 : 0.0 };
  ClipPlanes(mapper, s);
  style.ColourMapper = mapper;

  vtkTexture* texture = actor->GetTexture();
  s.Ids.push_back(texture);
  if (texture && !s.Invisible)
  {
    const TextureAlpha& alpha = this->TextureAlphaOf(texture);
    s.Key.insert(s.Key.end(), alpha.Key.begin(), alpha.Key.end());
    if (!alpha.Ok)
    {
      s.Note = "texture alpha not cut out (" + alpha.Why + "): casts the whole surface";
    }
    else if (alpha.Grid.HasCutouts() && !property->GetShowTexturesOnBackface())
    {
      s.Note = "texture alpha not cut out (ShowTexturesOnBackface off makes it depend on the "
               "facing): casts the whole surface";
    }
    else if (alpha.Grid.HasCutouts())
    {
      style.Texture = &alpha.Grid;
      if (vtkTransform* transform = texture->GetTransform())
      {
        style.TextureTransform = true;
        vtkMatrix4x4::DeepCopy(style.TextureMatrix, transform->GetMatrix());
        s.Key.insert(s.Key.end(), style.TextureMatrix, style.TextureMatrix + 16);
      }
    }
  }
  s.Key.push_back(property->GetShowTexturesOnBackface() ? 1.0 : 0.0);
  if (property->GetNumberOfTextures() > 0 && property->GetInterpolation() != VTK_PBR &&
    s.Note.empty())
  {
    s.Note = "the alpha of property textures is not cut out";
  }
  return s;
}

//------------------------------------------------------------------------------
bool vtkPenumbraSceneGeometry::Internals::Place(PropEntry&& candidate, const Settings& settings,
  unsigned char flags, const std::string& label, std::map<PathKey, PropEntry>& previous,
  std::string& error)
{
  PropEntry entry;
  bool reuse = false;
  auto found = previous.find(candidate.Path);
  if (found != previous.end())
  {
    PropEntry& old = found->second;
    reuse = old.Mapper == candidate.Mapper && old.Data == candidate.Data &&
      old.DataMTime == candidate.DataMTime && old.Attributes == candidate.Attributes &&
      old.AttributesMTime == candidate.AttributesMTime &&
      old.MapperMTime == candidate.MapperMTime &&
      std::equal(candidate.Matrix, candidate.Matrix + 16, old.Matrix) &&
      old.DrawKey == settings.Key && old.DrawIds == settings.Ids &&
      (!old.UsesWidth || SameWidths(candidate.Widths, old.Widths));
    entry = std::move(old);
    previous.erase(found);
  }
  if (!reuse)
  {
    TriangleList before = std::move(entry.Triangles);
    entry.Path = candidate.Path;
    entry.Leaf = candidate.Leaf;
    entry.PathRefs.assign(candidate.Path.begin(), candidate.Path.end());
    entry.Mapper = candidate.Mapper;
    entry.Data = candidate.Data;
    entry.DataMTime = candidate.DataMTime;
    entry.MapperMTime = candidate.MapperMTime;
    std::copy(candidate.Matrix, candidate.Matrix + 16, entry.Matrix);
    entry.Attributes = candidate.Attributes;
    entry.AttributesMTime = candidate.AttributesMTime;
    entry.DrawKey = settings.Key;
    entry.DrawIds = settings.Ids;
    std::copy(candidate.Widths, candidate.Widths + 3, entry.Widths);
    entry.What = candidate.What;
    ++this->ExtractedLastUpdate;
    if (!this->Extract(entry, settings, label, error))
    {
      return false; // not cached: the next Update looks at it again
    }
    entry.GeometryChanged = !(entry.Triangles == before);
    if (!entry.GeometryChanged)
    {
      // The same triangles: keep the stored ones, whose float32 copy Embree and GL buffers
      // read in place (nothing that reads them rebuilds while the geometry time stands still).
      entry.Triangles = std::move(before);
    }
  }
  else
  {
    entry.GeometryChanged = false;
  }
  entry.Flags = flags;
  if (!entry.Note.empty())
  {
    this->Note(entry.Leaf, label, entry.Note);
  }
  if (entry.UsesWidth && !(this->PixelSize > 0.0))
  {
    this->Note(
      entry.Leaf, label, "lines and points cast nothing: no pixel size (camera scale) was given");
  }
  auto inserted = this->Cache.emplace(entry.Path, std::move(entry));
  if (inserted.second)
  {
    this->Props.push_back(&inserted.first->second);
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkPenumbraSceneGeometry::Internals::KeepIfHidden(
  const PathKey& key, bool visible, std::map<PathKey, PropEntry>& previous)
{
  if (visible)
  {
    return false;
  }
  // The entry of a hidden prop stays as it is, so that showing it again is free.
  auto found = previous.find(key);
  if (found != previous.end())
  {
    this->Cache.emplace(key, std::move(found->second));
    previous.erase(found);
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkPenumbraSceneGeometry::Internals::VisitActor(const PathKey& key, vtkActor* actor,
  const double matrix[16], bool visible, unsigned char flags, const std::string& label,
  std::map<PathKey, PropEntry>& previous, std::string& error)
{
  if (this->KeepIfHidden(key, visible, previous))
  {
    return true;
  }
  vtkMapper* mapper = actor->GetMapper();
  vtkDataObject* data = UpdatedInput(mapper, !mapper || !mapper->GetStatic());
  if (!data)
  {
    return true;
  }
  PropEntry candidate = Candidate(key, actor, mapper, data, matrix);
  candidate.What = KindOf(mapper);
  candidate.Attributes = DisplayAttributes && vtkCompositeDataSet::SafeDownCast(data)
    ? DisplayAttributes(mapper)
    : nullptr;
  candidate.AttributesMTime = candidate.Attributes ? candidate.Attributes->GetMTime() : 0;

  Settings settings = this->ActorSettings(actor, mapper);
  candidate.Widths[0] = settings.Style.LineWidth;
  candidate.Widths[1] = settings.Style.PointSize;
  candidate.Widths[2] = settings.Style.EdgeWidth;
  if (auto* glyphs = vtkGlyph3DMapper::SafeDownCast(mapper))
  {
    // The helper mapper draws sources untextured with scalar colouring off; the instances'
    // colours come from the glyph mapper (AppendGlyphs). Sources are inputs of their own.
    settings.Style.ColourMapper = nullptr;
    settings.Style.Texture = nullptr;
    for (int i = 0; i < glyphs->GetNumberOfInputConnections(1); ++i)
    {
      vtkPolyData* source = glyphs->GetSource(i);
      settings.Ids.push_back(source);
      settings.Key.push_back(static_cast<double>(source ? source->GetMTime() : 0));
    }
  }
  if (candidate.What != Kind::Polygonal)
  {
    settings.Style.Texture = nullptr; // textures are applied to polydata mappers only
  }
  if (!this->Place(std::move(candidate), settings, flags, label, previous, error))
  {
    return false;
  }
  PropEntry& entry = this->Cache.find(key)->second;
  entry.Surface = actor->GetProperty()->GetRepresentation() == VTK_SURFACE;
  // Only a prop with both skipped fan triangles and strips depends on the cell map.
  entry.ExactCellMap = entry.Mappable && entry.Drawn && entry.Counts.StripTriangles > 0 &&
    entry.Counts.DrawnPolyTriangles != entry.Counts.PolyConservative &&
    UsesExactCellMap(mapper, actor, entry.Drawn);
  return true;
}

//------------------------------------------------------------------------------
bool vtkPenumbraSceneGeometry::Internals::VisitImage(const PathKey& key, vtkImageSlice* slice,
  const double matrix[16], bool visible, unsigned char flags, const std::string& label,
  std::map<PathKey, PropEntry>& previous, std::string& error)
{
  if (this->KeepIfHidden(key, visible, previous))
  {
    return true;
  }
  vtkImageMapper3D* mapper = slice->GetMapper();
  vtkDataObject* data = UpdatedInput(mapper, true);
  if (!data)
  {
    return true;
  }
  PropEntry candidate = Candidate(key, slice, mapper, data, matrix);
  candidate.What = Kind::Image;
  Settings settings;
  vtkImageProperty* property = slice->GetProperty();
  settings.Invisible = property && property->GetOpacity() == 0.0;
  settings.Key = { settings.Invisible ? 1.0 : 0.0,
    static_cast<double>(
      property && property->GetLookupTable() ? property->GetLookupTable()->GetMTime() : 0) };
  ClipPlanes(mapper, settings);
  return this->Place(std::move(candidate), settings, flags, label, previous, error);
}

//------------------------------------------------------------------------------
bool vtkPenumbraSceneGeometry::Internals::VisitPath(
  int propNumber, vtkAssemblyPath* path, std::map<PathKey, PropEntry>& previous, std::string& error)
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
  const unsigned char flags =
    static_cast<unsigned char>((casts ? CASTS_SHADOWS : 0) | (receives ? RECEIVES_SHADOWS : 0));
  vtkProp* leaf = path->GetLastNode()->GetViewProp();
  const std::string label = PropLabel(leaf, propNumber, key);
  // The world matrix: a plain prop's own, an assembly part's concatenated path matrix.
  double matrix[16];
  vtkMatrix4x4* m = key.size() > 1 ? path->GetLastNode()->GetMatrix() : leaf->GetMatrix();
  if (m)
  {
    vtkMatrix4x4::DeepCopy(matrix, m);
  }
  else
  {
    vtkMatrix4x4::Identity(matrix);
  }

  if (vtkSkybox::SafeDownCast(leaf))
  {
    return true; // drawn behind everything: it casts nothing, by design
  }
  if (auto* actor = vtkActor::SafeDownCast(leaf))
  {
    return this->VisitActor(key, actor, matrix, visible, flags, label, previous, error);
  }
  if (auto* slice = vtkImageSlice::SafeDownCast(leaf))
  {
    if (slice->IsA("vtkImageStack"))
    {
      this->Note(leaf, label, "image stacks are not reproduced: cast nothing");
      return true;
    }
    return this->VisitImage(key, slice, matrix, visible, flags, label, previous, error);
  }
  if (!visible)
  {
    return true;
  }
  if (vtkVolume::SafeDownCast(leaf))
  {
    this->Note(leaf, label, "volumes cast no shadows");
    return true;
  }
  // A composite prop: the actors it draws, each with its own matrix (vtkAxesActor, widget
  // representations, ...). 2D props draw no 3D geometry and are passed over silently.
  vtkNew<vtkPropCollection> parts;
  leaf->GetActors(parts);
  bool any = false;
  vtkCollectionSimpleIterator it;
  parts->InitTraversal(it);
  while (vtkProp* part = parts->GetNextProp(it))
  {
    auto* actor = vtkActor::SafeDownCast(part);
    if (!actor || actor == leaf || vtkSkybox::SafeDownCast(actor))
    {
      continue;
    }
    any = true;
    PathKey partKey = key;
    partKey.push_back(actor);
    double partMatrix[16];
    vtkMatrix4x4::DeepCopy(partMatrix, actor->GetMatrix());
    if (!this->VisitActor(partKey, actor, partMatrix, actor->GetVisibility() != 0, flags,
          PropLabel(actor, propNumber, partKey), previous, error))
    {
      return false;
    }
  }
  if (!any && vtkProp3D::SafeDownCast(leaf))
  {
    this->Note(leaf, label, "this prop class is not reproduced: casts nothing");
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkPenumbraSceneGeometry::Internals::Extract(
  PropEntry& e, const Settings& s, const std::string& label, std::string& message)
{
  e.Triangles.Clear();
  e.Mappable = false;
  e.Counts = penumbra_scene::PrimitiveCounts();
  e.Drawn = nullptr;
  e.Note = s.Note;
  e.UsesWidth = false;
  vtkMath::UninitializeBounds(e.Bounds);
  if (!Finite16(e.Matrix))
  {
    message = label + ": the prop matrix has NaN/inf entries";
    return false;
  }

  TriangleList drawn, casters;
  Outcome outcome;
  std::string note;
  if (!s.Invisible)
  {
    switch (e.What)
    {
      case Kind::Polygonal:
        this->ExtractPolygonal(e, s.Style, drawn, casters, outcome);
        break;
      case Kind::Glyphs:
        penumbra_scene::AppendGlyphs(vtkGlyph3DMapper::SafeDownCast(e.Mapper), e.Data, e.Matrix,
          s.Style, drawn, casters, outcome, note);
        break;
      case Kind::Splats:
        penumbra_scene::AppendSplats(vtkPointGaussianMapper::SafeDownCast(e.Mapper), e.Data,
          e.Matrix, s.Style, casters, outcome, note);
        break;
      case Kind::Image:
        penumbra_scene::AppendImageSlice(
          vtkImageSlice::SafeDownCast(e.Leaf), e.Matrix, s.Style, drawn, casters, outcome, note);
        break;
      case Kind::Unsupported:
        note = std::string(e.Mapper->GetClassName()) + " is not reproduced: casts nothing";
        break;
    }
  }
  if (!note.empty())
  {
    e.Note = e.Note.empty() ? note : e.Note + "; " + note;
  }
  if (outcome.BadPoints > 0)
  {
    message = label + ": " + std::to_string(outcome.BadPoints) +
      (outcome.BadPoints == 1 ? " point" : " points") + " with NaN/inf coordinates";
    return false;
  }
  if (outcome.BadTCoords > 0)
  {
    message = label + ": " + std::to_string(outcome.BadTCoords) +
      (outcome.BadTCoords == 1 ? " triangle" : " triangles") + " with NaN/inf texture coordinates";
    return false;
  }
  if (outcome.TooFine > 0)
  {
    const std::string fine =
      "texture cut-outs too fine to cut: " + std::to_string(outcome.TooFine) +
      " triangles cast whole";
    e.Note = e.Note.empty() ? fine : e.Note + "; " + fine;
  }
  e.UsesWidth = outcome.UsesWidth;
  e.PointsOrLines = outcome.PointsOrLines;
  // Caster owners already index the drawn triangles, which come first.
  if (drawn.Size() == 0)
  {
    e.Triangles = std::move(casters);
  }
  else
  {
    e.Triangles = std::move(drawn);
    e.Triangles.Append(casters, 0);
  }

  e.Triangles.ShrinkToFit();
  // The bounds of the triangles' corners (points no triangle uses are not stored).
  const std::vector<double>& world = e.Triangles.Points;
  if (e.Triangles.Size() > 0)
  {
    e.Bounds[0] = e.Bounds[2] = e.Bounds[4] = VTK_DOUBLE_MAX;
    e.Bounds[1] = e.Bounds[3] = e.Bounds[5] = VTK_DOUBLE_MIN;
    for (size_t i = 0; i < world.size(); i += 3)
    {
      for (int c = 0; c < 3; ++c)
      {
        e.Bounds[2 * c] = std::min(e.Bounds[2 * c], world[i + c]);
        e.Bounds[2 * c + 1] = std::max(e.Bounds[2 * c + 1], world[i + c]);
      }
    }
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkPenumbraSceneGeometry::Internals::ExtractPolygonal(PropEntry& e, const DrawStyle& style,
  TriangleList& drawn, TriangleList& casters, Outcome& outcome)
{
  vtkDataObject* data = e.Data;
  if (auto* composite = vtkCompositeDataSet::SafeDownCast(data))
  {
    // Composite inputs are drawn by vtkCompositePolyDataMapper2, which draws only the visible
    // polydata leaves. Cell ids continue from block to block in depth-first order, counting
    // every polydata leaf, hidden ones included.
    vtkIdType cellBase = 0;
    this->AppendBlocks(composite, true, e, style, cellBase, drawn, casters, outcome);
  }
  else if (auto* poly = vtkPolyData::SafeDownCast(data))
  {
    penumbra_scene::AppendDrawnPolyData(
      poly, e.Matrix, 0, style, drawn, casters, &e.Counts, outcome);
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
    penumbra_scene::AppendDrawnPolyData(
      surface, e.Matrix, 0, style, drawn, casters, &e.Counts, outcome);
    e.Mappable = true;
    e.Drawn = surface;
  }
}

//------------------------------------------------------------------------------
void vtkPenumbraSceneGeometry::Internals::AppendBlocks(vtkDataObject* block, bool parentVisible,
  PropEntry& e, const DrawStyle& style, vtkIdType& cellBase, TriangleList& drawn,
  TriangleList& casters, Outcome& outcome)
{
  // A block's own visibility if set, else its parent's (vtkCompositePolyDataMapper2's rule).
  vtkCompositeDataDisplayAttributes* attributes = e.Attributes;
  const bool visible = attributes && attributes->HasBlockVisibility(block)
    ? attributes->GetBlockVisibility(block)
    : parentVisible;
  if (auto* poly = vtkPolyData::SafeDownCast(block))
  {
    if (visible)
    {
      penumbra_scene::AppendDrawnPolyData(
        poly, e.Matrix, cellBase, style, drawn, casters, nullptr, outcome);
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
      this->AppendBlocks(
        it->GetCurrentDataObject(), visible, e, style, cellBase, drawn, casters, outcome);
    }
  }
}
