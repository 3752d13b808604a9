/**
 * @file    vtkPenumbraSceneInstances.h
 * @brief   Internal to Penumbra::Scene (not installed, not wrapped): props whose drawn shape
 *          is not their input's cells: glyph instances, point-gaussian splats, image slices.
 *
 * - vtkGlyph3DMapper (VTK 9.1 vtkOpenGLGlyph3DMapper::RebuildStructures): every input point
 *   not masked (a one-component vtkBitArray, Masking on) places its source (SourceIndexing:
 *   the norm of the index tuple, truncated and clamped) with translation to the point,
 *   rotation (Orient: ROTATION degrees z-x-y, DIRECTION, QUATERNION) and scale (Scaling:
 *   SCALE_BY_MAGNITUDE or SCALE_BY_COMPONENTS of the scale array, clamped into Range and
 *   normalized by it when Clamping, times ScaleFactor; a zero scale becomes 1e-10; no
 *   scaling at all when Scaling is off). The source is drawn by a polydata mapper with the
 *   actor's property, so every instance is extracted like a polydata (surfaces, lines,
 *   points, representation, clipping). Instances whose colour has alpha 0 are not drawn.
 *   Without a source VTK draws a unit line along x. Not reproduced: UseSourceTableTree (said
 *   in a note, nothing cast); level-of-detail sources (CullingAndLOD with LODs; VTK 9.1 has
 *   no public way to know whether LODs are set): every instance casts its full source.
 * - vtkPointGaussianMapper (vtkOpenGLPointGaussianMapper): with ScaleFactor 0 plain points
 *   (PointSize pixels) at the splat centres; otherwise each splat is a camera-facing
 *   triangle whose inscribed circle has radius r = s * ScaleFactor * TriangleScale, s the
 *   ScaleArray component (its magnitude for another component; 1 without the array) mapped
 *   by ScaleFunction. The default splat shader multiplies the alpha by a Gaussian and
 *   discards nothing, so the whole triangle is drawn; whatever the camera it covers the disc
 *   of radius r, which each splat casts as a point solid of diameter 2 r. Splat centres are
 *   the vertex cells' points (every point without vertex cells); clipping keeps or drops a
 *   splat by its centre. Splats receive nothing.
 * - vtkImageSlice with a vtkImageSliceMapper: the displayed slice (SliceNumber along the
 *   Orientation axis, the image extent cropped by CroppingRegion, half a pixel more with
 *   Border) as a quad that casts and receives; its pixels' alpha is not cut out (noted when
 *   it can be 0). A slice that follows the camera (SliceFacesCamera, SliceAtFocalPoint),
 *   other image mappers and image stacks: nothing cast, noted.
 */

#ifndef vtkPenumbraSceneInstances_h
#define vtkPenumbraSceneInstances_h

#include "vtkPenumbraSceneDrawn.h"

#include <string>

class vtkDataObject;
class vtkGlyph3DMapper;
class vtkImageSlice;
class vtkPointGaussianMapper;

namespace penumbra_scene
{
/**
 * Appends every glyph instance of `mapper` (input `data`, prop matrix `m`) as the polydata
 * `style` draws. Returns false when the input has non-finite values (`outcome` counts them);
 * `note` receives what is not cast as drawn.
 */
void AppendGlyphs(vtkGlyph3DMapper* mapper, vtkDataObject* data, const double m[16],
  const DrawStyle& style, TriangleList& drawn, TriangleList& casters, Outcome& outcome,
  std::string& note);

/// Appends the splats of `mapper` (input `data`) as caster-only point solids.
void AppendSplats(vtkPointGaussianMapper* mapper, vtkDataObject* data, const double m[16],
  const DrawStyle& style, TriangleList& casters, Outcome& outcome, std::string& note);

/// Appends the displayed slice of `slice` (matrix `m`) as two triangles.
void AppendImageSlice(vtkImageSlice* slice, const double m[16], const DrawStyle& style,
  TriangleList& drawn, TriangleList& casters, Outcome& outcome, std::string& note);
}

#endif
