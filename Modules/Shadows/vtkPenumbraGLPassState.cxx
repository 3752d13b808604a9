#include "vtkPenumbraGLPassState.h"

#include "vtkOpenGLFramebufferObject.h"
#include "vtkTextureObject.h"

namespace penumbra_gl
{
//------------------------------------------------------------------------------
ScopedPassState::ScopedPassState(
  vtkOpenGLState* state, vtkOpenGLFramebufferObject* fbo, int width, int height)
  : State(state)
  , Blend(state, GL_BLEND)
  , DepthTest(state, GL_DEPTH_TEST)
  , Scissor(state, GL_SCISSOR_TEST)
  , Cull(state, GL_CULL_FACE)
  , Viewport(state)
  , DepthFunc(state)
  , DepthMask(state)
  , ColorMask(state)
{
  state->PushFramebufferBindings();
  fbo->Bind();
  state->vtkglViewport(0, 0, width, height);
  state->vtkglDisable(GL_SCISSOR_TEST);
  state->vtkglDisable(GL_BLEND);
  state->vtkglDisable(GL_CULL_FACE);
}

//------------------------------------------------------------------------------
ScopedPassState::~ScopedPassState()
{
  this->State->PopFramebufferBindings();
}

//------------------------------------------------------------------------------
MapRenderState::MapRenderState(
  vtkOpenGLState* state, vtkOpenGLFramebufferObject* fbo, int width, int height, bool colorWrites)
  : ScopedPassState(state, fbo, width, height)
{
  state->vtkglEnable(GL_DEPTH_TEST);
  state->vtkglDepthFunc(GL_LESS);
  state->vtkglDepthMask(GL_TRUE);
  const GLboolean color = colorWrites ? GL_TRUE : GL_FALSE;
  state->vtkglColorMask(color, color, color, color);
  this->HadClamp = glIsEnabled(GL_DEPTH_CLAMP) == GL_TRUE;
  glEnable(GL_DEPTH_CLAMP);
}

//------------------------------------------------------------------------------
MapRenderState::~MapRenderState()
{
  glBindVertexArray(0);
  if (!this->HadClamp)
  {
    glDisable(GL_DEPTH_CLAMP);
  }
}

//------------------------------------------------------------------------------
QuadPassState::QuadPassState(vtkOpenGLState* state, vtkOpenGLFramebufferObject* fbo,
  const std::vector<vtkTextureObject*>& targets, int width, int height, vtkTextureObject* depth)
  : ScopedPassState(state, fbo, width, height)
{
  for (size_t a = 0; a < targets.size(); ++a)
  {
    fbo->AddColorAttachment(static_cast<unsigned int>(a), targets[a]);
  }
  if (depth)
  {
    fbo->AddDepthAttachment(depth);
  }
  else
  {
    fbo->RemoveDepthAttachment();
  }
  fbo->ActivateDrawBuffers(static_cast<unsigned int>(targets.size()));
  state->vtkglColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  state->vtkglDepthMask(GL_FALSE);
  if (depth)
  {
    state->vtkglEnable(GL_DEPTH_TEST);
    state->vtkglDepthFunc(GL_GREATER);
  }
  else
  {
    state->vtkglDisable(GL_DEPTH_TEST);
  }
}
}
