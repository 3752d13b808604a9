#include "vtkPenumbraShadowPassInternals.h"

#include "vtkOpenGLPolyDataMapper.h"
#include "vtkPenumbraMapperDraws.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkShaderProgram.h"
#include "vtkTextureObject.h"
#include "vtk_glew.h"

#include "vtkPenumbraVisibilityDec.h"

using namespace penumbra_shadow_pass;

vtkMTimeType vtkPenumbraShadowPass::GetShaderStageMTime()
{
  return this->Impl->ShaderTime.GetMTime();
}

bool vtkPenumbraShadowPass::PreReplaceShaderValues(
  std::string&, std::string&, std::string& fragmentShader, vtkAbstractMapper* mapper, vtkProp* prop)
{
  // Translucent props read the translucent layer's visibility: the opaque samples hold the
  // surface behind them.
  // A prop can hold this pass twice in its keys (an actor drawn by itself and as the part of
  // an assembly, which lends the part its own keys): the code goes in once.
  const bool placed = fragmentShader.find(LayerTags[0]) != std::string::npos ||
    fragmentShader.find(LayerTags[1]) != std::string::npos;
  if (!placed && !this->Impl->Injected.empty() && vtkOpenGLPolyDataMapper::SafeDownCast(mapper) &&
    vtkPenumbraShadowKeys::ReceivesShadows(prop))
  {
    const int layer = IsTranslucentReceiver(prop) ? 1 : 0;
    vtkShaderProgram::Substitute(fragmentShader, "//VTK::Light::Dec",
      std::string("//VTK::Light::Dec\n") + LayerTags[layer] + "\n", false);
    vtkShaderProgram::Substitute(fragmentShader, "//VTK::UniformFlow::Impl",
      std::string("//VTK::UniformFlow::Impl\n") + SurfaceTag + "\n", false);
    vtkShaderProgram::Substitute(fragmentShader, "//VTK::Light::Impl",
      std::string(ReceiveTag) + "\n//VTK::Light::Impl", false);
  }
  return true;
}

bool vtkPenumbraShadowPass::PostReplaceShaderValues(
  std::string&, std::string&, std::string& fragmentShader, vtkAbstractMapper* mapper, vtkProp* prop)
{
  int layer = 0;
  while (layer < 2 && fragmentShader.find(LayerTags[layer]) == std::string::npos)
  {
    ++layer;
  }
  if (layer == 2)
  {
    return true;
  }
  const std::string tag = LayerTags[layer];
  // Only surfaces drawn as triangles receive: lines and points are lit as VTK lights them
  // (vtkPenumbraMapperDraws.h), and so is every light this shader does not shade with.
  const bool surface = penumbra_draws::DrawsSurface(mapper, prop);
  const bool position = penumbra_draws::HasViewPosition(fragmentShader);
  // After VTK's light uniforms: rename each shadowed light's colour to colour x visibility.
  // A macro naming itself is not expanded again, so `lightColorN` inside it is the uniform.
  std::string dec = vtkPenumbraVisibilityDec;
  std::string lookups, visibilities;
  const Internals& impl = *this->Impl;
  for (size_t i = 0; surface && i < impl.Injected.size(); ++i)
  {
    const std::string color = "lightColor" + std::to_string(i);
    if (impl.Injected[i].empty() || !penumbra_draws::LightsWith(fragmentShader, i))
    {
      continue; // light i is unshadowed, or this shader does not light with it
    }
    if (vtkPenumbraFrame::ShaderLookup* lookup = impl.InjectedLookup(i))
    {
      if (!position)
      {
        continue; // no surface to look up: no view sample either (unshadowed)
      }
      // Evaluated once before VTK's lighting (which reads the colour twice).
      const std::string suffix = LookupSuffix(i);
      lookups += lookup->GetSource(suffix);
      visibilities += "  float penumbraVisibility" + suffix + " = penumbraReceiver == 1 ? " +
        "penumbraReceive" + suffix + "(penumbraP, penumbraN) : 1.0;\n";
      dec += "#define " + color + " (" + color + " * penumbraVisibility" + suffix + ")\n";
      continue;
    }
    const std::string sampler = LayerSamplers[layer] + std::to_string(i);
    dec += "uniform sampler2D " + sampler + ";\n";
    dec += "#define " + color + " (" + color + " * penumbraShadow(texelFetch(" + sampler +
      ", penumbraTexel(), 0).r))\n";
  }
  std::string surfaceCall;
  if (!lookups.empty())
  {
    // Props without view samples (vtkPenumbraViewSamplesPass::GivesSamples()) are lit
    // unshadowed, as the visibility textures give them: set per draw, since props share
    // shaders.
    dec = "uniform int penumbraReceiver;\n" + lookups + dec;
    surfaceCall = vtkPenumbraViewSamplesPass::GetSurfaceCall();
    // The lookups' facing rules are in double precision, like the reference's.
    if (fragmentShader.find("GL_ARB_gpu_shader_fp64") == std::string::npos)
    {
      vtkShaderProgram::Substitute(fragmentShader, "//VTK::System::Dec",
        "//VTK::System::Dec\n#extension GL_ARB_gpu_shader_fp64 : require\n", false);
    }
    // A template without VTK's uniform-flow tag computes the surface before the lookups.
    if (fragmentShader.find(SurfaceTag) == std::string::npos)
    {
      visibilities = surfaceCall + visibilities;
    }
  }
  if (!lookups.empty())
  {
    vtkPenumbraViewSamplesPass::AddSurfaceDeclarations(fragmentShader, tag, dec);
  }
  vtkShaderProgram::Substitute(fragmentShader, tag, surface ? dec : "", false);
  vtkShaderProgram::Substitute(fragmentShader, SurfaceTag, surfaceCall, false);
  vtkShaderProgram::Substitute(fragmentShader, ReceiveTag, visibilities, false);
  return true;
}

bool vtkPenumbraShadowPass::SetShaderParameters(
  vtkShaderProgram* program, vtkAbstractMapper*, vtkProp* prop, vtkOpenGLVertexArrayObject*)
{
  Internals& impl = *this->Impl;
  if (impl.Injected.empty())
  {
    return true;
  }
  if (program->IsUniformUsed("penumbraVCToRebased"))
  {
    impl.SamplesPass->SetSurfaceUniforms(program);
    if (program->IsUniformUsed("penumbraReceiver"))
    {
      program->SetUniformi("penumbraReceiver", impl.SamplesPass->GivesSamples(prop) ? 1 : 0);
    }
    for (size_t i = 0; i < impl.Injected.size(); ++i)
    {
      if (vtkPenumbraFrame::ShaderLookup* lookup = impl.InjectedLookup(i))
      {
        lookup->SetUniforms(program, LookupSuffix(i));
      }
    }
  }
  if (!program->IsUniformUsed("penumbraViewportOrigin"))
  {
    return true;
  }
  // The visibility texel of a pixel is its offset from the current viewport's corner; this
  // holds for the window and for the translucency passes' own framebuffers alike.
  GLint viewport[4] = { 0, 0, 0, 0 };
  glGetIntegerv(GL_VIEWPORT, viewport);
  const int origin[2] = { viewport[0], viewport[1] };
  program->SetUniform2i("penumbraViewportOrigin", origin);
  for (int layer = 0; layer < 2; ++layer)
  {
    for (size_t i = 0; i < impl.Injected.size(); ++i)
    {
      const std::string name = LayerSamplers[layer] + std::to_string(i);
      if (impl.Injected[i] != "texture" || !program->IsUniformUsed(name.c_str()))
      {
        continue; // (asking a shader lookup for its texture would run its pass mid-draw)
      }
      vtkTextureObject* tex = impl.Frame->GetVisibilityTexture(layer, static_cast<int>(i));
      if (tex)
      {
        program->SetUniformi(name.c_str(), tex->GetTextureUnit());
      }
    }
  }
  return true;
}
