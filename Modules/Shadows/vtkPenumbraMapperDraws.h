/**
 * @file   vtkPenumbraMapperDraws.h
 * @brief  What a prop's drawing gives the shadow passes: whether it goes through the render-pass
 *         shader hooks, whether the draw being built is a surface, and which lights a finished
 *         fragment shader shades with.
 *
 * The one place the view-sample pass and the shadow pass decide which draws get view samples
 * and shadowed lighting, so that what the samples record and what the shading reads cannot
 * disagree:
 *
 * - Only triangles drawn as triangles receive shadows. Lines and points (line and vertex
 *   cells, the wireframe and points representations, vertex visibility, point-gaussian
 *   splats, tubes and sphere imposters) are lit as VTK lights them: a line has no surface a
 *   facing rule could test, and it lies inside the tube it casts (vtkPenumbraSceneGeometry).
 * - Only props whose drawing calls the hooks with the prop itself can be sampled and shaded;
 *   the others (image slices, skyboxes, composite annotation props, anything drawing through
 *   an actor of its own) are drawn unchanged and only occlude the samples behind them.
 */

#ifndef vtkPenumbraMapperDraws_h
#define vtkPenumbraMapperDraws_h

#include <string> // For LightsWith

class vtkAbstractMapper;
class vtkProp;

namespace penumbra_draws
{
/**
 * Whether the draw `mapper` is building or issuing right now (inside a render-pass hook of a
 * vtkOpenGLPolyDataMapper and its subclasses) rasterizes triangles: VTK 9.1's
 * GetOpenGLMode() of the prop's representation and the primitive being drawn is
 * GL_TRIANGLES and it is not the vertex-visibility draw. False for any other mapper, and for
 * the imposter mappers that draw points as triangles (point-gaussian splats, sphere and stick
 * mappers).
 */
bool DrawsSurface(vtkAbstractMapper* mapper, vtkProp* prop);

/**
 * Whether `prop`'s opaque and translucent drawing calls the render passes' shader hooks with
 * `prop` itself: a visible vtkActor (followers, LOD actors and assembly parts included) whose
 * mapper is a vtkOpenGLPolyDataMapper (composite, sphere, stick mappers ...), a
 * vtkGlyph3DMapper, a vtkPointGaussianMapper or a vtkDataSetMapper, and that is not a vtkSkybox
 * (which draws its cube through an actor of its own); and a vtkAssembly, whose parts VTK draws
 * with the assembly's keys.
 */
bool DrawsThroughHooks(vtkProp* prop);

/**
 * Whether a finished fragment shader (after VTK's substitutions) shades with light `index`:
 * it declares the light's colour and uses it in its code. VTK declares the lights of the
 * renderer's lighting complexity in every shader, lit or not (an unlit line keeps
 * `uniform vec3 lightColor0;` and never reads it).
 */
bool LightsWith(const std::string& fragmentShader, size_t index);

/** Whether a fragment shader has VTK's view-coordinate position `vertexVC`. */
bool HasViewPosition(const std::string& fragmentShader);
}

#endif
