/**
 * @file    vtkPenumbraGLPassState.h
 * @brief   Scoped GL state for the techniques' own passes: every pass into a framebuffer of
 *          its own saves, sets and restores the state it touches (RAII), so that VTK's state
 *          cache and the renderer's drawing are left as they were.
 *
 * Not wrapped and not installed.
 */

#ifndef vtkPenumbraGLPassState_h
#define vtkPenumbraGLPassState_h

#include "vtkOpenGLState.h" // For the scoped state savers
#include "vtk_glew.h"

#include <vector>

class vtkOpenGLFramebufferObject;
class vtkTextureObject;

namespace penumbra_gl
{
/**
 * The GL state every pass of the techniques into its own framebuffer saves and sets: the
 * framebuffer bindings (pushed, `fbo` bound), blending, depth test and function, depth and
 * colour masks, scissor, culling and viewport; blending, scissor and culling off, viewport
 * width x height. Everything is restored when the object goes out of scope.
 */
class ScopedPassState
{
public:
  ScopedPassState(vtkOpenGLState* state, vtkOpenGLFramebufferObject* fbo, int width, int height);
  ~ScopedPassState();
  ScopedPassState(const ScopedPassState&) = delete;
  ScopedPassState& operator=(const ScopedPassState&) = delete;

protected:
  vtkOpenGLState* State;

private:
  vtkOpenGLState::ScopedglEnableDisable Blend;
  vtkOpenGLState::ScopedglEnableDisable DepthTest;
  vtkOpenGLState::ScopedglEnableDisable Scissor;
  vtkOpenGLState::ScopedglEnableDisable Cull;
  vtkOpenGLState::ScopedglViewport Viewport;
  vtkOpenGLState::ScopedglDepthFunc DepthFunc;
  vtkOpenGLState::ScopedglDepthMask DepthMask;
  vtkOpenGLState::ScopedglColorMask ColorMask;
};

/**
 * GL state for drawing a light view into `fbo` (size x size): depth test LESS with writes,
 * colour writes as asked, both windings drawn (open meshes have no back faces), and
 * GL_DEPTH_CLAMP so that casters before the near plane are clamped, not clipped (Brabec 2003,
 * ch. 4.1.2; Hertel et al. 2009, §3). Restored when the object goes out of scope.
 */
class MapRenderState : public ScopedPassState
{
public:
  MapRenderState(vtkOpenGLState* state, vtkOpenGLFramebufferObject* fbo, int size, bool colorWrites)
    : MapRenderState(state, fbo, size, size, colorWrites)
  {
  }
  MapRenderState(vtkOpenGLState* state, vtkOpenGLFramebufferObject* fbo, int width, int height,
    bool colorWrites);
  ~MapRenderState();

private:
  bool HadClamp = false;
};

/**
 * GL state for a full-viewport pass into colour targets (a vtkOpenGLQuadHelper draw):
 * `targets` as colour attachments 0.. (all drawn, all channels written), no depth attachment
 * unless `depth` is given, which is then tested GREATER without writes (a quad at depth 1
 * passes only where that depth buffer holds a surface). Restored when the object goes out
 * of scope.
 */
class QuadPassState : public ScopedPassState
{
public:
  QuadPassState(vtkOpenGLState* state, vtkOpenGLFramebufferObject* fbo,
    const std::vector<vtkTextureObject*>& targets, int width, int height,
    vtkTextureObject* depth = nullptr);
};
}

#endif
// VTK-HeaderTest-Exclude: vtkPenumbraGLPassState.h
