/**
 * @class   vtkPenumbraSceneGeometry
 * @brief   World-space triangles of a renderer's props, in double precision, for shadow
 *          techniques and the exact reference.
 *
 * Update() walks the renderer's view props (all of them, not only those inside the camera
 * frustum: a prop off screen still casts shadows into the view) and turns what each visible
 * prop draws into world-space triangles, with the prop's full matrix applied in double
 * precision, read relative to a rebasing Origin. The triangles are stored once, indexed, in
 * world coordinates (vtkPenumbraSceneTriangles.h: points shared by a mesh's triangles are
 * stored once; about 31 bytes a triangle for a closed mesh with its float32 copy).
 *
 * The rule: every prop casts what VTK 9.1 draws of it, and only that (the table per prop
 * kind is docs/prop-contract.md). Surfaces are drawn triangles; what is drawn but is
 * not a surface triangle becomes caster-only triangles:
 * - vtkActor with vtkPolyDataMapper, vtkCompositePolyDataMapper(2) or vtkDataSetMapper
 *   (non-polydata inputs go through a default vtkDataSetSurfaceFilter, as vtkDataSetMapper
 *   does), composite inputs (polydata leaves in depth-first order, as the composite mappers
 *   draw them), vtkAssembly parts (with their path matrices). Polygons are fanned and strips
 *   triangulated as VTK draws them. Line cells, the edges of a wireframe representation and
 *   of strips cast tubes LineWidth pixels wide; vertex cells and every point of the points
 *   representation cast small solids PointSize pixels wide (RenderLinesAsTubes and
 *   RenderPointsAsSpheres draw the same widths); a surface drawn with EdgeVisibility casts
 *   the flat strips VTK grows beyond its polygons' edges, and VertexVisibility adds its
 *   points. A wireframe or points representation casts no solid triangles. A pixel's world
 *   size is taken at the camera's focal point (SetPixelSize()), so orbiting the camera does
 *   not change what is cast; zooming or resizing re-extracts only the props that draw lines
 *   or points.
 * - Alpha: VTK discards fragments whose final alpha is 0. A prop with Opacity 0 casts
 *   nothing; a triangle whose scalar colours have alpha 0 at all its corners (or whose cell
 *   colour has) casts nothing; an actor texture with texels of alpha 0 (RGBA or
 *   luminance-alpha, through its lookup table otherwise) cuts its triangles exactly to the
 *   drawn region of texture space (nearest: the texel squares with alpha > 0; linear: the
 *   texel-centre cells with a corner of alpha > 0; wrap modes and the texture transform as
 *   VTK applies them; 1D and 2D texture coordinates). Translucent surfaces (alpha > 0) cast
 *   like opaque ones.
 * - Clipping planes (mapper->GetClippingPlanes(), the first 6 as VTK): triangles are cut
 *   exactly, lines along their length, points by their centre.
 * - vtkGlyph3DMapper instances with the mapper's own placement, cast and receive like any
 *   triangles; vtkPointGaussianMapper splats cast a solid covering each splat's drawn disc
 *   and receive nothing; vtkImageSlice (vtkImageSliceMapper) casts its displayed slice quad.
 * - Casts nothing: vtkVolume, vtkSkybox (drawn behind everything), 2D actors, invisible props,
 *   props without mapper or input. A composite 3D prop (vtkAxesActor, a widget
 *   representation, ...) casts the actors its GetActors() gives, with their own matrices.
 * A visible 3D prop that is drawn but casts nothing or less than it draws gets a casting note
 * (GetCastingNote()). Hidden blocks of composite data (vtkCompositeDataDisplayAttributes, a
 * block inheriting its parent's visibility unless set, as vtkCompositePolyDataMapper2 draws
 * them) are skipped too, once a display-attributes accessor is registered
 * (SetDisplayAttributesAccessor(): the mapper that holds them is a RenderingOpenGL2 class,
 * which this module must not depend on; Penumbra's Rendering module registers it when
 * loaded).
 *
 * Per prop the drawn triangles come first, in the order the G-buffer's primitive ids count
 * them, then the prop's caster-only triangles (tubes, point solids, splats, and the pieces
 * of drawn triangles that cast only in part: such a triangle keeps RECEIVES_SHADOWS and
 * loses CASTS_SHADOWS, and its pieces cast). GetTriangleOwner() names, per triangle, the drawn
 * triangle whose view samples it must never shadow.
 *
 * Triangle order follows what VTK 9.1's vtkOpenGLPolyDataMapper draws, so that a G-buffer
 * pass can turn `gl_PrimitiveID + PrimitiveIDOffset` into a global triangle index with
 * MapPrimitiveId() (the rule is documented there).
 *
 * Rebasing: Origin is the centre of the world bounds of all triangles, each coordinate
 * rounded to a multiple of 2^k metres, 2^k being the smallest power of two not below 1/16 of
 * the largest extent and at least 1 m (exact in double, and (vertex - Origin) is then exact
 * for vertices near it). Once chosen it is kept by later updates as long as the bounds'
 * centre stays within one extent (at least 1 m) of it on every axis and the extent has not
 * grown or shrunk by more than a factor of 4 since; an update without triangles keeps it
 * too. So one prop moving does not make it jitter. Positions within a few kilometres of
 * Origin keep millimetres in float32, whatever the georeferenced coordinates (1e6..1e7 m).
 *
 * Caching: each prop's input is first brought up to date (mapper->Update(), unless the
 * mapper is Static). A prop whose input data object, data MTime, mapper MTime, matrix values
 * and drawing settings (representation, widths in pixels, edges, opacity zero or not,
 * texture, clipping planes) did not change since the previous Update(), and, if it draws
 * lines or points, whose world line and point widths did not change, is not re-extracted;
 * GetNumberOfPropsExtractedLastUpdate() tells how many were. Hidden props keep their cached
 * triangles, so showing them again costs nothing; colour, material and flag changes never
 * re-extract. GetGeometryTime() changes only when the published triangles change (positions,
 * topology, the visible prop set, or Origin), GetFlagsTime() when the per-triangle flags do.
 *
 * Bad input (NaN or infinite coordinates of drawn points, glyph placements, splat sizes or
 * texture coordinates) makes Update() return 0 with a message naming the prop
 * (GetErrorMessage(), also reported with vtkErrorMacro) and empties the geometry so nothing
 * renders silently wrong. A scene without triangles is not an error.
 */

#ifndef vtkPenumbraSceneGeometry_h
#define vtkPenumbraSceneGeometry_h

#include "vtkObject.h"
#include "vtkPenumbraSceneModule.h" // For export macro

#include <memory> // For std::unique_ptr

#ifndef __VTK_WRAP__
#include "vtkPenumbraSceneTriangles.h" // For penumbra::SceneTriangles
#endif

class vtkCamera;
class vtkCompositeDataDisplayAttributes;
class vtkDoubleArray;
class vtkInformationStringKey;
class vtkMapper;
class vtkProp;
class vtkPropCollection;
class vtkRenderer;

class VTKPENUMBRASCENE_EXPORT vtkPenumbraSceneGeometry : public vtkObject
{
public:
  static vtkPenumbraSceneGeometry* New();
  vtkTypeMacro(vtkPenumbraSceneGeometry, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Bits of GetTriangleFlags().
   */
  enum TriangleFlags
  {
    CASTS_SHADOWS = 1,
    RECEIVES_SHADOWS = 2
  };

  /**
   * Extracts the triangles of the renderer's view props (renderer->GetViewProps()). Returns
   * 1 on success, 0 on error (see GetErrorMessage()); on error the geometry is emptied.
   * First sets PixelSize from the renderer's active camera and tiled viewport height
   * (ComputePixelSize()) when the renderer has a camera and a window of non-zero size;
   * otherwise the PixelSize set last is used.
   */
  int Update(vtkRenderer* renderer);

  ///@{
  /**
   * World length (scene units, e.g. metres) of one pixel at the camera's focal point: the
   * scale that turns LineWidth and PointSize (pixels) into the world width of caster tubes
   * and point solids. Update(props, count) uses the value set here; Update(renderer)
   * computes it first. Default 0: lines and points cast nothing (and say so in a note).
   */
  vtkSetMacro(PixelSize, double);
  vtkGetMacro(PixelSize, double);
  ///@}

  /**
   * The world size of one pixel at the focal point of `camera` for a viewport of `width` x
   * `height` pixels: 2 d tan(ViewAngle / 2) / height with d the camera-focal point distance
   * (width instead of height with UseHorizontalViewAngle), or 2 ParallelScale / height for a
   * parallel projection. 0 for a null camera or an empty viewport.
   */
  static double ComputePixelSize(vtkCamera* camera, int width, int height);

  ///@{
  /**
   * Props that cast shadows without being drawn by the renderer, e.g. the casters of other
   * MPI ranks in a distributed render (the ParaView plugin's view gathers them). They are not
   * in the renderer, so nothing draws them and they give no view samples; Update(renderer)
   * extracts them after the renderer's view props, like any other prop (shadow keys,
   * visibility and caching apply). Default: none.
   */
  void SetShadowOnlyProps(vtkPropCollection* props);
  vtkPropCollection* GetShadowOnlyProps();
  ///@}

#ifndef __VTK_WRAP__
  /**
   * Same for an explicit prop list, e.g. the one a render pass gets from vtkRenderState.
   * Beware that vtkRenderState holds only the props that survived frustum culling, while
   * props outside the view still cast shadows into it.
   */
  int Update(vtkProp** props, int count);
#endif

  /**
   * How to find a mapper's block visibilities (vtkCompositeDataDisplayAttributes), nullptr
   * when it has none. One accessor per process; Penumbra::Shadows registers the one for
   * vtkCompositePolyDataMapper2. Without an accessor every block is extracted.
   */
#ifndef __VTK_WRAP__
  using DisplayAttributesAccessor = vtkCompositeDataDisplayAttributes* (*)(vtkMapper*);
  static void SetDisplayAttributesAccessor(DisplayAttributesAccessor accessor);
#endif

  /**
   * The problem found by the last Update(), empty after a success.
   */
  const char* GetErrorMessage();

  /**
   * Rebasing origin in world coordinates (metres): every vertex is stored minus it. Default
   * (0, 0, 0) until an Update() finds triangles; see the class description for the rule.
   */
  vtkGetVector3Macro(Origin, double);

  /**
   * Number of extracted triangles (degenerate ones included).
   */
  vtkIdType GetNumberOfTriangles();

#ifndef __VTK_WRAP__
  /**
   * The published triangles (vtkPenumbraSceneTriangles.h): per prop its points in world
   * coordinates and its indexed triangles, and by global triangle index the corners relative
   * to Origin in double precision (Get, GetLocal), their float32 rounding (GetFloat), the
   * flags, owners, cell ids and prop indices described below. Valid until the next Update().
   * Triangle order: the props in extraction order, per prop its drawn triangles, then its
   * caster-only ones.
   */
  const penumbra::SceneTriangles& GetTriangles();
#endif

  /**
   * Triangle `t`'s corners v0 xyz, v1 xyz, v2 xyz: world position minus Origin, in double
   * precision, in VTK's vertex order (the triangle's winding is kept). False (and zeros) for
   * an index out of range. For scripts and tests; C++ loops read GetTriangles().
   */
  bool GetTriangle(vtkIdType t, double vertices[9]);

  /**
   * Triangle `t`'s flags: bit 0 (CASTS_SHADOWS, value 1) = casts shadows, bit 1
   * (RECEIVES_SHADOWS, value 2) = receives shadows: what the triangle does (a drawn triangle
   * receives and casts unless cut, a caster-only triangle only casts) masked by
   * vtkPenumbraShadowKeys. 0 out of range.
   */
  int GetTriangleFlags(vtkIdType t);

  /**
   * The global index of the drawn triangle triangle `t` belongs to, whose view samples it
   * must never shadow (the one own-triangle exclusion of the tracer and the techniques): the
   * triangle itself for a drawn triangle, the drawn triangle a caster piece was cut from
   * (clipping planes, alpha cut-outs, a surface's edge strips), -1 for shapes that belong to
   * no drawn triangle (tubes, point solids, splats: lines and points receive no shadows) and
   * out of range. A sample whose triangle is unknown (-1) excludes nothing.
   */
  vtkIdType GetTriangleOwner(vtkIdType t);

  /**
   * The id of the VTK cell triangle `t` comes from in its prop's polydata (verts, lines,
   * polys, strips numbered in that order, as vtkPolyData does; after surface extraction for
   * non-polydata; for composite data each polydata leaf's ids continue after the previous
   * leaf's, in depth-first order). For glyph instances and splats: the input point id. Tubes,
   * point solids and cut pieces carry the cell they were made from. -1 out of range.
   */
  vtkIdType GetTriangleCellId(vtkIdType t);

  /**
   * The index of triangle `t`'s prop in the extracted prop list (see GetProp()), -1 out of
   * range.
   */
  int GetTrianglePropIndex(vtkIdType t);

  /**
   * Bytes the stored triangles hold (points, corners, cell ids, owners, roles, float32
   * positions), for the memory reports.
   */
  size_t GetTriangleBytes();

  ///@{
  /**
   * The extracted props: visible vtkActors that have a mapper with input (with triangles or
   * not), in view-prop order, the parts of a vtkAssembly in path-traversal order. For an
   * assembly part GetProp() returns the part actor (the leaf of its assembly path).
   */
  int GetNumberOfProps();
  vtkProp* GetProp(int index);
  ///@}

  ///@{
  /**
   * Range of a prop's triangles in the global triangle list: they are contiguous, the drawn
   * ones first, then the caster-only ones. -1 / 0 for an invalid index.
   */
  vtkIdType GetPropTriangleOffset(int index);
  vtkIdType GetPropTriangleCount(int index);
  ///@}

  /**
   * Index of a prop (as an actor, or as an assembly part actor) in the extracted list, -1 if
   * absent. For an actor used in several assembly paths the first one.
   */
  int GetPropIndex(vtkProp* prop);

  ///@{
  /**
   * Casting notes of the last Update(): one per visible 3D prop that is drawn but casts
   * nothing or less (or other) than it draws, e.g. a volume, an unsupported glyph setting,
   * an image slice cast solid, an unknown prop class. GetCastingNote() names the prop like
   * the error messages (`vtkVolume 'ct' (prop 2): volumes cast no shadows`).
   */
  int GetNumberOfCastingNotes();
  vtkProp* GetCastingNoteProp(int index);
  const char* GetCastingNote(int index);
  ///@}

  /**
   * Global triangle index of the triangle that VTK 9.1's vtkOpenGLPolyDataMapper draws as
   * `primitiveId` (= gl_PrimitiveID + the mapper's PrimitiveIDOffset uniform) for prop
   * `propIndex`; -1 if that primitive is not one of our triangles (a vertex or line
   * primitive), is out of range, if the prop is not drawn as a surface (wireframe / points
   * representation), is not drawn by a polydata mapper (glyphs, splats, image slices:
   * instanced or drawn by other mappers), or if its input is composite:
   * vtkCompositePolyDataMapper2 orders its blocks by polydata pointer (std::map<vtkPolyData*,
   * ...>) and groups them by array layout, so its numbering cannot be reproduced. A prop's
   * caster-only triangles follow its drawn ones: no primitive id maps to them.
   *
   * The rule mirrored (VTK 9.1, surface representation, checked by rendering):
   * - vtkOpenGLPolyDataMapper::RenderPieceDraw draws the cell arrays in the order verts,
   *   lines, polys, strips; the offset of each is vtkOpenGLCellToVTKCellMap's primitive
   *   offset: verts start at 0 with one point primitive per point id, lines follow with one
   *   segment per consecutive point pair, then the polygon triangles, then the strip
   *   triangles.
   * - Polygons are fanned (p0, p_i, p_i+1); fan triangles with two coincident points (equal
   *   coordinates) are not drawn (vtkOpenGLIndexBufferObject::AppendTriangleIndexBuffer). We
   *   keep them in our list; no primitive id maps to them.
   * - Strips give triangle j = (p_j, p_j+1+j%2, p_j+1+(j+1)%2), all drawn.
   * - The strips' offset counts n-2 triangles per polygon, skipped ones included, unless the
   *   mapper has cell scalars or cell normals (it then builds its full cell map, counting only
   *   drawn triangles); Update() evaluates which case applies for every prop.
   */
  vtkIdType MapPrimitiveId(int propIndex, vtkIdType primitiveId);

  /**
   * The first primitive id (gl_PrimitiveID + PrimitiveIDOffset, as for MapPrimitiveId) that
   * VTK 9.1 draws as a triangle for prop `propIndex`: the primitives below it are points and
   * lines, whose fragments are not surfaces (they receive no shadows). The vertex and line
   * primitive count for a polydata drawn as a surface; 0 when the prop draws triangles only
   * (surfaces without vertex or line cells, image slices); VTK_ID_MAX when it draws no
   * triangle (wireframe and points representations, splats); -1 when it cannot be told
   * (composite data or glyphs that draw points or lines besides triangles, unknown props).
   * Vertices shown with VertexVisibility are drawn after the strips with the strips' offset,
   * so they cannot be told apart by primitive id.
   */
  vtkIdType GetFirstSurfacePrimitive(int propIndex);

  /**
   * Changes only when the triangles change: positions, topology, the set of visible props or
   * Origin (not when only flags change). 0 before any triangle was published.
   */
  vtkMTimeType GetGeometryTime();

  /**
   * Changes when the per-triangle flags change: caster/receiver flags, or the triangle list
   * itself (e.g. a prop shown or hidden).
   */
  vtkMTimeType GetFlagsTime();

  /**
   * The later of GetGeometryTime() and GetFlagsTime(): the one stamp a cache of the casters
   * (an acceleration structure, a caster list, a shadow map's key) compares. VTK time stamps
   * come from one global counter, so it changes whenever either of the two does, and two
   * geometries share a value only while neither has published anything (0). It covers Origin
   * and the number of triangles too: Update() moves GetGeometryTime() whenever either changes.
   */
  vtkMTimeType GetCastersTime();

  /**
   * How many props the last Update() (re)extracted from their data: 0 when nothing changed.
   */
  int GetNumberOfPropsExtractedLastUpdate();

  /**
   * The triangles flagged CASTS_SHADOWS (caster-only ones included), in absolute world
   * coordinates exactly as extracted (double, before rebasing: no Origin round trip), 9
   * components per triangle, in the order of the global list. `world` is resized to fit.
   */
  void GetCasterWorldTriangles(vtkDoubleArray* world);

  /**
   * Number of zero-area triangles (kept in the list, in their place): those whose largest
   * angle has a sine below 1e-12, coincident points included. Duplicate triangles are kept
   * too and are not counted separately.
   */
  vtkIdType GetNumberOfDegenerateTriangles();

  /**
   * Whether triangle `index` can block light: it casts shadows and has a non-zero, finite
   * area (zero-area triangles cover no solid angle). Every technique and the reference use
   * this one rule to pick occluders.
   */
  bool IsOccluder(vtkIdType index);

  /**
   * World bounds (xmin, xmax, ymin, ymax, zmin, zmax) of all triangles, grown to
   * SetSceneBounds() when there are any; uninitialized bounds (vtkMath::UninitializeBounds)
   * when there are none.
   */
  void GetBounds(double bounds[6]);

  /**
   * Bounds of the whole scene this geometry holds a part of (a distributed render, where
   * each rank holds its own triangles and only the others' that can shadow them; nullptr or
   * uninitialized bounds: none). The next Update() grows GetBounds() to them, so the
   * rebasing origin and the epsilons relative to the scene (penumbra_rules::SceneDiagonal)
   * are those of the whole scene on every rank, as in a single process.
   */
  void SetSceneBounds(const double bounds[6]);

  /**
   * Optional prop name used in error messages (`vtkActor 'tower' (prop 3): ...`), stored in
   * the prop's property keys like vtkPenumbraShadowKeys' flags. Default: none (messages then
   * say `unnamed vtkActor (prop 3)`). An assembly's name is used for unnamed parts.
   */
  static vtkInformationStringKey* NAME();
  static void SetPropName(vtkProp* prop, const char* name);
  static const char* GetPropName(vtkProp* prop);

protected:
  vtkPenumbraSceneGeometry();
  ~vtkPenumbraSceneGeometry() override;

  double Origin[3];
  double PixelSize = 0.0;

private:
  vtkPenumbraSceneGeometry(const vtkPenumbraSceneGeometry&) = delete;
  void operator=(const vtkPenumbraSceneGeometry&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

namespace penumbra
{
/**
 * What a cache of the casters was built from: which geometry, at which GetCastersTime().
 * Changed() is true before the first Remember(), after Forget() (a build that failed
 * halfway), and once that geometry moved on or another one is given.
 */
struct CastersStamp
{
  bool Changed(vtkPenumbraSceneGeometry* geometry) const
  {
    return !this->Valid || geometry != this->Geometry || geometry->GetCastersTime() != this->Time;
  }
  void Remember(vtkPenumbraSceneGeometry* geometry)
  {
    this->Valid = true;
    this->Geometry = geometry;
    this->Time = geometry->GetCastersTime();
  }
  void Forget() { this->Valid = false; }

  bool Valid = false;
  vtkPenumbraSceneGeometry* Geometry = nullptr; // identity only, never dereferenced
  vtkMTimeType Time = 0;
};
}

#endif
