/**
 * @file    vtkPenumbraConservativeMapCPU.h
 * @brief   Conservative shadow map layers built on the CPU (private to
 *          vtkPenumbraConservativeShadows).
 *
 * The same map the conservative technique's geometry-shader program draws (Hertel et al. 2009,
 * §4.1), produced by exact conservative rasterization in double precision with vtkSMPTools:
 * per texel, the `layers` nearest caster triangles whose projection overlaps the texel
 * square (grown by a quarter texel for the float rounding of the reference's rays),
 * each with a conservative minimum light depth over that square (§4.1). Separating-axis
 * overlap instead of the paper's enlarged triangle (§4.1), so no texel is kept that
 * the square does not touch, and no explicit depth writes that defeat a rasterizer's early
 * depth test.
 *
 * Why on the CPU: the target rasterizer is Mesa's llvmpipe, i.e. the same two CPU cores.
 * There the geometry-shader path pays for every primitive and texel in the GL pipeline
 * (explicit gl_FragDepth, one full draw per peeled layer, a full read back); the CPU builds
 * all layers in one pass over binned tiles, in double precision and without a read back.
 *
 * Triangles that reach the apex region of a perspective view (w < NearW: a light on or very
 * near a surface) are not rasterized; they are returned in `nearTriangles` for an exact
 * per-sample test, since their projection would cover (almost) the whole view.
 *
 * The same rasterization serves the irregular z-buffer of linked-list shadow maps (Ferko 2014;
 * Johnson et al. 2005) through RasterizeConservative(): there every overlapping texel/triangle
 * pair tests the triangle against the view samples listed at that texel.
 *
 * Not wrapped and not installed.
 */

#ifndef vtkPenumbraConservativeMapCPU_h
#define vtkPenumbraConservativeMapCPU_h

#include "vtkPenumbraCasterBuffers.h"  // For penumbra_casters::CasterIds
#include "vtkPenumbraSceneTriangles.h" // For penumbra::SceneTriangles
#include "vtkType.h"

#include <cstdint>
#include <functional>
#include <vector>

namespace penumbra_light_views
{
struct View;
}

namespace penumbra_conservative
{
/** Statistics of one map build. */
struct CpuMapStats
{
  vtkIdType Triangles = 0;   // casters that reached the view's frustum
  vtkIdType TexelTests = 0;  // texel/triangle overlap tests
  vtkIdType TexelWrites = 0; // texel/triangle pairs that overlapped
  vtkIdType VisitWork = 0;   // RasterizeConservative: the sum of the visitor's answers
};

/**
 * Builds `layers` map layers of size x size texels for `view`: depth[k][texel] (the view's
 * stored-depth unit, +inf when empty) and ids[k][texel] (triangle id + 1, 0 when empty),
 * sorted by depth per texel. `triangles` are the scene's (rebased frame), `casters` the ids of
 * the triangles that cast. Triangles reaching the apex region are appended to `nearTriangles`
 * instead.
 */
CpuMapStats BuildConservativeMap(const penumbra_light_views::View& view, int size, int layers,
  const penumbra::SceneTriangles& triangles, const penumbra_casters::CasterIds& casters,
  std::vector<float>* depth, std::vector<std::uint32_t>* ids,
  std::vector<vtkIdType>& nearTriangles);

/**
 * Called for each texel/triangle pair whose overlap the rasterization cannot rule out, with
 * the triangle's conservative (never too large) stored depth over the texel; returns the work
 * it did (summed into CpuMapStats::VisitWork). Calls run in parallel over tiles of texels; all
 * calls for one texel come from one thread, in caster order.
 */
using TexelVisitor = std::function<vtkIdType(size_t texel, vtkIdType triangle, float depth)>;

/**
 * The rasterization of BuildConservativeMap() with `visit` in place of the map writes. Texels
 * with `active[texel] == 0` are skipped (their tiles bin no triangles); `active` may change
 * during the call for texels the visitor owns, and null means all texels are active.
 * Triangles reaching the apex region are appended to `nearTriangles` instead.
 */
CpuMapStats RasterizeConservative(const penumbra_light_views::View& view, int size,
  const penumbra::SceneTriangles& triangles, const penumbra_casters::CasterIds& casters,
  const unsigned char* active, std::vector<vtkIdType>& nearTriangles, const TexelVisitor& visit);
}

#endif
// VTK-HeaderTest-Exclude: vtkPenumbraConservativeMapCPU.h
