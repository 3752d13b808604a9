// Resolution-matched shadow maps' lookup (Lefohn et al. 2007, §3.3.1): the samples read
// through the page table, and the uniforms of the programs that read the virtual map.
#include "vtkPenumbraResolutionMatchedShadowsInternals.h"

namespace
{
constexpr double MaxTangent = 1000.0; // the slope bias's cap, as shadowmap's

double Norm3(const double* v)
{
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}
}
//------------------------------------------------------------------------------
// The uniforms the request and lookup programs share: the G-buffer, the facing rules and the
// virtual map's view and levels.
void vtkPenumbraResolutionMatchedShadows::Internals::SetMapUniforms(
  vtkPenumbraResolutionMatchedShadows* self, vtkShaderProgram* program,
  vtkPenumbraViewSamplesPass* gbuffer, const LightSetup& setup, bool anyCaster)
{
  program->SetUniformi("samplePositions", gbuffer->GetPositionTexture()->GetTextureUnit());
  program->SetUniformi("sampleNormals", gbuffer->GetNormalTexture()->GetTextureUnit());
  program->SetUniformi("lightKind", setup.Type == LightSetup::Kind::Directional ? 0 : 2);
  program->SetUniformi("lightOff", setup.Off ? 1 : 0);
  program->SetUniformi("anyCaster", anyCaster ? 1 : 0);
  penumbra_light_views::SetClassifyUniforms(program, setup);
  float matrix[16];
  this->Cur->Map.ToFloatMatrix(matrix);
  program->SetUniformMatrix4x4("lightMatrix", matrix);
  program->SetUniformi("perspective", this->Cur->Map.Perspective ? 1 : 0);
  program->SetUniformf("invFar", static_cast<float>(1.0 / this->Cur->Map.Far));
  program->SetUniformi("baseLevel", this->Levels.Base);
  program->SetUniformi("minLevel", self->GetMinimumRequestLevel());
  program->SetUniformi("finestLevel", this->Levels.Finest);
  program->SetUniformi("lodBias", self->LODBias);
  program->SetUniformi("analysisStep", self->AnalysisStep);
  program->SetUniformi("footprintWidth", self->Footprint == FOOTPRINT_WIDTH ? 1 : 0);
}

//------------------------------------------------------------------------------
// §3.3.1: every layer's samples looked up through the page table into light k's visibility
// channel (the facing rules decide the others).
bool vtkPenumbraResolutionMatchedShadows::Internals::Lookup(
  vtkPenumbraResolutionMatchedShadows* self, vtkPenumbraFrame* frame, int k,
  const LightSetup& setup, bool anyCaster, std::string& error)
{
  vtkOpenGLRenderWindow* win = frame->GetWindow();
  vtkOpenGLQuadHelper* quad = this->LookupQuads[self->Filter == FILTER_BILINEAR ? 1 : 0].get();
  vtkShaderProgram* program = quad->Program;
  if (!anyCaster)
  {
    // The programs read the textures only for pending samples, which there are none of; the
    // uniforms still need a view (the identity).
    this->Cur->Map = View();
    for (int r = 0; r < 4; ++r)
    {
      this->Cur->Map.Row[r][r] = 1.0;
    }
  }
  else if (this->Cur->RequestTargets.size() < 2 * static_cast<size_t>(frame->GetNumberOfLayers()))
  {
    error = "the lookup has no requests for some layer of the frame";
    return false;
  }
  for (int layer = 0; layer < frame->GetNumberOfLayers(); ++layer)
  {
    vtkPenumbraViewSamplesPass* gbuffer = frame->GetLayer(layer);
    vtkPenumbraFrame::VisibilityTarget target = frame->BindVisibilityTarget(layer, k);
    win->GetShaderCache()->ReadyShaderProgram(program);
    gbuffer->GetPositionTexture()->Activate();
    gbuffer->GetNormalTexture()->Activate();
    int step = 1;
    vtkTextureObject* levels = anyCaster
      ? this->Cur->LevelTarget(static_cast<size_t>(layer), self->AnalysisStep, step)
      : gbuffer->GetPositionTexture(); // not read: no sample is pending
    levels->Activate();
    this->SetMapUniforms(self, program, gbuffer, setup, anyCaster);
    this->SetLookupUniforms(self, program, levels, step, setup);
    quad->Render();
    this->Cur->PageTableAlias->Deactivate();
    this->Atlas->Deactivate();
    if (anyCaster)
    {
      levels->Deactivate();
    }
    gbuffer->GetPositionTexture()->Deactivate();
    gbuffer->GetNormalTexture()->Deactivate();
  }
  return true;
}

//------------------------------------------------------------------------------
// The uniforms of the programs that read the pages (refine and lookup): the sample levels
// (`levels`, bound, one per levelStep x levelStep pixels), the atlas and page table (bound
// here), and the bias.
void vtkPenumbraResolutionMatchedShadows::Internals::SetLookupUniforms(
  vtkPenumbraResolutionMatchedShadows* self, vtkShaderProgram* program, vtkTextureObject* levels,
  int levelStep, const LightSetup& setup)
{
  this->Atlas->Activate();
  this->Cur->PageTableAlias->Activate();
  program->SetUniformi("requests", levels->GetTextureUnit());
  program->SetUniformi("levelStep", levelStep);
  program->SetUniformi("atlas", this->Atlas->GetTextureUnit());
  program->SetUniformi("pageTable", this->Cur->PageTableAlias->GetTextureUnit());
  program->SetUniformi(
    "slotsPerRowBits", FloorLog2(static_cast<int>(this->Atlas->GetWidth()) >> PageBits));
  program->SetUniformf("tanHalf", static_cast<float>(this->Cur->Map.TanHalf));
  program->SetUniformf("footprintScale",
    static_cast<float>(
      std::max(2.0 / Norm3(this->Cur->Map.Row[0]), 2.0 / Norm3(this->Cur->Map.Row[1]))));
  program->SetUniformf("depthPerLengthOrtho", static_cast<float>(Norm3(this->Cur->Map.Row[2])));
  penumbra_light_views::SetLightUniforms(program, setup);
  program->SetUniformf("constantBias", static_cast<float>(self->Bias));
  program->SetUniformf("slopeBias", static_cast<float>(self->SlopeBias));
  program->SetUniformf("maxTangent", static_cast<float>(MaxTangent));
}
