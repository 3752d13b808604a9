/**
 * @file    vtkPenumbraSceneGeometryInternals.h
 * @brief   Internal to Penumbra::Scene (not installed, not wrapped): the state of a
 *          vtkPenumbraSceneGeometry, shared by its two files: vtkPenumbraSceneGeometry.cxx
 *          (the public API, rebasing and publishing the global arrays) and
 *          vtkPenumbraSceneGeometryProps.cxx (visiting the props and extracting each).
 */

#ifndef vtkPenumbraSceneGeometryInternals_h
#define vtkPenumbraSceneGeometryInternals_h

#include "vtkPenumbraSceneGeometry.h"

#include "vtkPenumbraSceneCasters.h"
#include "vtkPenumbraSceneCutouts.h"
#include "vtkPenumbraSceneDrawn.h"

#include "vtkAbstractMapper.h"
#include "vtkCompositeDataDisplayAttributes.h"
#include "vtkDataObject.h"
#include "vtkDataSetSurfaceFilter.h"
#include "vtkDoubleArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkPolyData.h"
#include "vtkProp.h"
#include "vtkPropCollection.h"
#include "vtkSmartPointer.h"
#include "vtkTexture.h"
#include "vtkTimeStamp.h"
#include "vtkUnsignedCharArray.h"

#include <map>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

class vtkActor;
class vtkAssemblyPath;
class vtkImageSlice;

namespace penumbra_scene
{
// How a prop's drawn shape is made (see vtkPenumbraSceneInstances.h).
enum class Kind
{
  Polygonal, // a polydata, dataset or composite mapper: its cells as drawn
  Glyphs,
  Splats,
  Image,
  Unsupported // drawn by a mapper whose shape is not reproduced: casts nothing, noted
};

// Everything kept about one extracted prop (an actor, or one assembly path to a part actor).
// Triangles are stored in absolute world coordinates so that a new Origin needs no
// re-extraction.
struct PropEntry
{
  // Identity: the props of the assembly path, root first (a single prop for a plain actor).
  std::vector<vtkProp*> Path;
  vtkSmartPointer<vtkProp> Leaf;
  std::vector<vtkSmartPointer<vtkProp>> PathRefs; // keep the path's props alive with the key

  // What the extraction depended on; all unchanged means the triangles are still right.
  vtkSmartPointer<vtkAbstractMapper> Mapper;
  vtkSmartPointer<vtkDataObject> Data;
  vtkMTimeType DataMTime = 0;
  vtkMTimeType MapperMTime = 0;
  double Matrix[16];
  vtkSmartPointer<vtkCompositeDataDisplayAttributes> Attributes; // block visibilities, if any
  vtkMTimeType AttributesMTime = 0;
  std::vector<double> DrawKey;      // the drawing settings (see Settings)
  std::vector<const void*> DrawIds; // objects they name (texture, glyph sources)
  double Widths[3] = { 0, 0, 0 };   // world line, point and edge widths extracted with
  bool UsesWidth = false;           // lines or points drawn: the widths matter
  bool PointsOrLines = false;       // some of its fragments come from points or lines

  Kind What = Kind::Polygonal;
  TriangleList Triangles;             // the drawn triangles first, then the caster-only ones
  double RebasedFor[3] = { 0, 0, 0 }; // the origin Triangles.Rebased was made for
  double Bounds[6];
  std::string Note; // what the extraction could not cast as drawn

  // VTK 9.1 primitive numbering of the polydata the mapper draws (see MapPrimitiveId).
  bool Mappable = false; // a single polydata drawn by a polydata mapper
  penumbra_scene::PrimitiveCounts Counts;
  vtkSmartPointer<vtkPolyData> Drawn; // the single polydata drawn, to re-check colouring

  // Re-evaluated by every Update (cheap, and not part of the geometry).
  unsigned char Flags = 0;
  bool Surface = true;
  bool ExactCellMap = false;
  bool GeometryChanged = false; // by the current Update
};

using PathKey = std::vector<vtkProp*>;

// What a prop draws with (DrawStyle) and the values that decide it, compared between updates.
struct Settings
{
  DrawStyle Style;
  std::vector<double> Key;
  std::vector<const void*> Ids;
  bool Invisible = false; // Opacity 0: VTK discards every fragment
  std::string Note;
};

// An actor texture's alpha, read once per texture and image MTime.
struct TextureAlpha
{
  vtkSmartPointer<vtkTexture> Texture;
  std::vector<double> Key;
  AlphaGrid Grid;
  bool Ok = true;
  std::string Why;
  bool Used = false;
};
}

struct vtkPenumbraSceneGeometry::Internals
{
  using PropEntry = penumbra_scene::PropEntry;
  using PathKey = penumbra_scene::PathKey;
  using Settings = penumbra_scene::Settings;
  using TextureAlpha = penumbra_scene::TextureAlpha;
  using DrawStyle = penumbra_scene::DrawStyle;
  using Outcome = penumbra_scene::Outcome;
  using TriangleList = penumbra_scene::TriangleList;

  // Where a composite mapper keeps its block visibilities (SetDisplayAttributesAccessor()).
  static DisplayAttributesAccessor DisplayAttributes;

  std::string ErrorMessage;
  penumbra::SceneTriangles Triangles; // the published view of the props' lists

  std::map<PathKey, PropEntry> Cache; // every prop seen by the last Update, visible or not
  std::vector<PropEntry*> Props;      // the extracted list, in order
  std::vector<vtkIdType> Offsets;     // first global triangle of each prop
  std::unordered_map<vtkProp*, int> IndexOfLeaf;
  std::vector<std::pair<vtkSmartPointer<vtkProp>, std::string>> Notes;
  std::map<vtkTexture*, TextureAlpha> Textures;

  vtkTimeStamp GeometryTime;
  vtkTimeStamp FlagsTime;
  int ExtractedLastUpdate = 0;
  vtkIdType Degenerate = 0;
  double Bounds[6];
  double PixelSize = 0.0; // of the current Update

  bool HaveOrigin = false;
  double OriginExtent = 0.0; // the extent the current Origin was chosen for

  // Signature of the last published content, to tell real changes from no-ops.
  std::vector<std::pair<PathKey, vtkIdType>> PublishedLayout;
  std::vector<unsigned char> PublishedPropFlags;

  vtkNew<vtkDataSetSurfaceFilter> Surface;
  double SceneBounds[6]; // SetSceneBounds(); uninitialized: none
  vtkSmartPointer<vtkPropCollection> ShadowOnly;

  Internals()
  {
    vtkMath::UninitializeBounds(this->Bounds);
    vtkMath::UninitializeBounds(this->SceneBounds);
  }

  // One path of a view prop: dispatches its leaf. Returns false with `error` on bad input.
  bool VisitPath(int propNumber, vtkAssemblyPath* path, std::map<PathKey, PropEntry>& previous,
    std::string& error);
  // An actor (or a composite prop's part actor) drawn with `matrix`.
  bool VisitActor(const PathKey& key, vtkActor* actor, const double matrix[16], bool visible,
    unsigned char flags, const std::string& label, std::map<PathKey, PropEntry>& previous,
    std::string& error);
  bool VisitImage(const PathKey& key, vtkImageSlice* slice, const double matrix[16], bool visible,
    unsigned char flags, const std::string& label, std::map<PathKey, PropEntry>& previous,
    std::string& error);
  // Keeps the cached entry of a hidden prop; true when the prop is hidden.
  bool KeepIfHidden(const PathKey& key, bool visible, std::map<PathKey, PropEntry>& previous);
  // Reuses the cached entry of `key` or extracts it again, then lists it.
  bool Place(PropEntry&& candidate, const Settings& settings, unsigned char flags,
    const std::string& label, std::map<PathKey, PropEntry>& previous, std::string& error);

  Settings ActorSettings(vtkActor* actor, vtkMapper* mapper);
  const TextureAlpha& TextureAlphaOf(vtkTexture* texture);
  void Note(vtkProp* prop, const std::string& label, const std::string& note);

  // Re-extracts an entry from its mapper's input. Returns false with `message` on bad input.
  bool Extract(PropEntry& e, const Settings& s, const std::string& label, std::string& message);
  void ExtractPolygonal(PropEntry& e, const DrawStyle& style, TriangleList& drawn,
    TriangleList& casters, Outcome& outcome);
  // Appends the visible polydata leaves below `block` (depth first), advancing cellBase
  // past hidden ones too.
  void AppendBlocks(vtkDataObject* block, bool parentVisible, PropEntry& e, const DrawStyle& style,
    vtkIdType& cellBase, TriangleList& drawn, TriangleList& casters, Outcome& outcome);

  void ChooseOrigin(double origin[3]);
  void Publish(double origin[3], bool geometryChanged);
  void Clear();
};

#endif
