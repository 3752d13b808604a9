// The shadow maps' lookup: on the CPU, over the pending-sample list, over the frame's
// G-buffer and in the receivers' shaders, with the soft (PCSS, area) modes' uniforms.
#include "vtkPenumbraShadowMapShadowsInternals.h"

#include "vtkPenumbraGLPassState.h"
#include "vtkPenumbraShadowMapClassify.h"
#include "vtkPenumbraShadowMapCompare.h"
#include "vtkPenumbraShadowMapFrameFS.h"
#include "vtkPenumbraShadowMapLookupFS.h"
#include "vtkPenumbraShadowMapReceive.h"
#include "vtkPenumbraShadowMapSoft.h"
#include "vtkPenumbraShadowMapTileSample.h"

namespace
{
// Slope-scaled bias stops growing here (0.057 degrees from grazing): a receiver exactly
// edge-on to the light would otherwise get an infinite bias. Lower caps leave grazing
// receivers in their own shadow at every resolution (a cap of 20, 87 degrees, left 33 % of
// torture/grazing_light's lit samples shadowed at 2048² and 4096²; this cap: 1.5 % and
// 0.26 % at 2048² and 8192², 640 x 480).
constexpr double MaxTangent = 1000.0;

// Fast PCF (Brabec 2003, ch. 5.2): the 2 x 2 texels around the continuous map position
// (ms, mt) in [-1, 1], compared with `threshold` and weighted bilinearly; the taps stay
// inside the map like PCF's. vtkPenumbraShadowMapCompare.glsl has the float twin.
double BilinearLookup(
  const std::vector<float>& map, int width, int height, double ms, double mt, double threshold)
{
  const double fx = (ms * 0.5 + 0.5) * width - 0.5;
  const double fy = (mt * 0.5 + 0.5) * height - 0.5;
  const double bx = std::floor(fx), by = std::floor(fy);
  const double wx = fx - bx, wy = fy - by;
  auto lit = [&](double x, double y)
  {
    const int ix = std::min(width - 1, std::max(0, static_cast<int>(x)));
    const int iy = std::min(height - 1, std::max(0, static_cast<int>(y)));
    return map[static_cast<size_t>(iy) * width + ix] >= threshold ? 1.0 : 0.0;
  };
  const double bottom = (1.0 - wx) * lit(bx, by) + wx * lit(bx + 1.0, by);
  const double top = (1.0 - wx) * lit(bx, by + 1.0) + wx * lit(bx + 1.0, by + 1.0);
  return (1.0 - wy) * bottom + wy * top;
}
}

namespace penumbra_shadow_maps
{
// A program's source with the shared GLSL pieces in place. Only the facing rules (Classify)
// use double precision, so only programs with them need GL_ARB_gpu_shader_fp64 (core since
// GL 4.0): the tile programs run where it is missing.
std::string ComposeShader(const char* source)
{
  std::string fs = source;
  if (fs.find("//PENUMBRA::Classify") != std::string::npos)
  {
    vtkShaderProgram::Substitute(fs, "//VTK::System::Dec",
      "//VTK::System::Dec\n#extension GL_ARB_gpu_shader_fp64 : require\n", false);
  }
  vtkShaderProgram::Substitute(fs, "//PENUMBRA::Classify", vtkPenumbraShadowMapClassify, false);
  vtkShaderProgram::Substitute(fs, "//PENUMBRA::TileSample", vtkPenumbraShadowMapTileSample, false);
  vtkShaderProgram::Substitute(fs, "//PENUMBRA::Compare", vtkPenumbraShadowMapCompare, false);
  vtkShaderProgram::Substitute(fs, "//PENUMBRA::Soft", vtkPenumbraShadowMapSoft, false);
  return fs;
}
}

namespace
{
// An orthographic view's texel in world units, its larger side (the maps may be non-square):
// the footprint of the slope-scaled bias.
double OrthoFootprint(const View& view, const LightMaps& m)
{
  return std::max(2.0 / (Norm3(view.Row[0]) * m.Width), 2.0 / (Norm3(view.Row[1]) * m.Height));
}

// The uniforms of one slot's view (vtkPenumbraShadowMapCompare.glsl).
// `suffix` ends every name (see penumbra_light_views::SuffixGlobals).
void SetSlotUniforms(
  vtkShaderProgram* program, const LightMaps& m, int slot, const std::string& suffix = "")
{
  auto name = [&suffix](const char* base) { return base + suffix; };
  program->SetUniformi(name("slot").c_str(), slot);
  if (m.Paraboloid)
  {
    program->SetUniformf(name("invFar").c_str(), static_cast<float>(1.0 / m.Far));
    return;
  }
  const View& view = m.Views[static_cast<size_t>(slot)];
  float matrix[16];
  view.ToFloatMatrix(matrix);
  program->SetUniformMatrix4x4(name("lightMatrix").c_str(), matrix);
  program->SetUniformf(name("invFar").c_str(), static_cast<float>(1.0 / view.Far));
  program->SetUniformf(name("tanHalf").c_str(), static_cast<float>(view.TanHalf));
  program->SetUniformf(name("footprintScale").c_str(), static_cast<float>(OrthoFootprint(view, m)));
  program->SetUniformf(name("depthPerLengthOrtho").c_str(), static_cast<float>(Norm3(view.Row[2])));
}

// A depth map read as raw depth on its own texture unit (every lookup's texelFetch compare,
// vtkPenumbraShadowMapCompare.glsl), through a sampler object that turns the texture's
// compare mode off; also bound for programs that read no map, so that the sampler2D never
// shares a unit with the G-buffer's samplers.
class RawDepthBinding
{
public:
  RawDepthBinding(vtkOpenGLRenderWindow* win, GLuint& sampler, vtkTextureObject* map)
  {
    if (!sampler)
    {
      glGenSamplers(1, &sampler);
      glSamplerParameteri(sampler, GL_TEXTURE_COMPARE_MODE, GL_NONE);
      glSamplerParameteri(sampler, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glSamplerParameteri(sampler, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
      glSamplerParameteri(sampler, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glSamplerParameteri(sampler, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    // An alias of the map (not owning its handle), bound through VTK so that its texture
    // unit bookkeeping stays right; the sampler object overrides the compare mode there.
    // Its parameters are the map's (VTK sends them to the shared texture on binding).
    this->Alias->SetContext(win);
    this->Alias->SetMinificationFilter(vtkTextureObject::Nearest);
    this->Alias->SetMagnificationFilter(vtkTextureObject::Nearest);
    this->Alias->SetWrapS(vtkTextureObject::ClampToEdge);
    this->Alias->SetWrapT(vtkTextureObject::ClampToEdge);
    this->Alias->SetDepthTextureCompare(true);
    this->Alias->SetDepthTextureCompareFunction(vtkTextureObject::Lequal);
    this->Alias->AssignToExistingTexture(map->GetHandle(), GL_TEXTURE_2D);
    this->Alias->Activate();
    glBindSampler(static_cast<GLuint>(this->Alias->GetTextureUnit()), sampler);
  }
  ~RawDepthBinding()
  {
    glBindSampler(static_cast<GLuint>(this->Alias->GetTextureUnit()), 0);
    this->Alias->Deactivate();
  }
  int GetUnit() { return this->Alias->GetTextureUnit(); }

private:
  vtkNew<vtkTextureObject> Alias;
};
}
//------------------------------------------------------------------------------
// The lookup program a light needs (see LookupVariant); maps is null when no sample is
// pending (no map is read).
LookupVariant vtkPenumbraShadowMapShadows::Internals::Variant(
  vtkPenumbraShadowMapShadows* self, const LightSetup& setup, bool anyCaster, const LightMaps* maps)
{
  LookupVariant v;
  v.LightKind = setup.Type == LightSetup::Kind::Directional
    ? 0
    : (setup.Type == LightSetup::Kind::Spot ? (setup.Area ? 3 : 2) : 1);
  v.LightOff = setup.Off ? 1 : 0;
  v.AnyCaster = anyCaster ? 1 : 0;
  if (!maps)
  {
    return v;
  }
  v.SlotMode = this->SlotMode(self, setup);
  // Every view of a light has the same projection (one view, or perspective cube faces).
  v.Perspective = !maps->Paraboloid && !maps->Views.empty() && maps->Views[0].Perspective ? 1 : 0;
  v.Bilinear = self->Filter == FILTER_BILINEAR ? 1 : 0;
  v.Radius = v.Bilinear ? 0 : TapRadius(self);
  v.AreaMode = SoftMode(self, *maps);
  return v;
}

//------------------------------------------------------------------------------
// Per-sample lookup on the GPU for a CPU sample set (Brabec 2003, ch. 5: hardware depth
// compare): the pending samples as a compacted list, one fragment each, one draw per slot.
bool vtkPenumbraShadowMapShadows::Internals::LookupList(vtkPenumbraShadowMapShadows* self,
  const penumbra_light_views::FrameInputs& in, const LightSetup& setup, const LightMaps& m,
  const unsigned char* state, float* vis, std::string& error)
{
  vtkOpenGLRenderWindow* win = in.Window;
  const vtkIdType n = in.NumberOfSamples;
  const float* nrm = in.Normals;
  // ---- Per-sample lookup on the GPU (Brabec 2003, ch. 5: hardware depth compare): the
  // pending samples as a compacted list, one fragment each, one draw per slot.
  std::vector<vtkIdType>& list = this->List;
  list.clear();
  for (vtkIdType s = 0; s < n; ++s)
  {
    if (state[s] == Pending)
    {
      list.push_back(s);
    }
  }
  const vtkIdType count = static_cast<vtkIdType>(list.size());
  const int listWidth = static_cast<int>(std::min<vtkIdType>(count, 2048));
  const int listHeight = static_cast<int>((count + listWidth - 1) / listWidth);
  std::vector<float>& positions = this->ListPositionData;
  std::vector<float>& normals = this->ListNormalData;
  positions.assign(static_cast<size_t>(4) * listWidth * listHeight, 0.0f);
  normals.assign(positions.size(), 0.0f);
  vtkSMPTools::For(0, count,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType i = begin; i < end; ++i)
      {
        const vtkIdType s = list[static_cast<size_t>(i)];
        double p[3];
        SamplePoint(in, s, p);
        for (int c = 0; c < 3; ++c)
        {
          positions[static_cast<size_t>(4 * i + c)] = static_cast<float>(p[c]);
          normals[static_cast<size_t>(4 * i + c)] = nrm[3 * s + c];
        }
      }
    });
  if (!this->LookupFBO)
  {
    this->LookupFBO = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
    this->LookupFBO->SetContext(win);
    this->ListPositions = Internals::FloatTexture(win);
    this->ListNormals = Internals::FloatTexture(win);
    this->ListVisibility = Internals::FloatTexture(win);
  }
  for (vtkTextureObject* tex : { this->ListPositions.Get(), this->ListNormals.Get() })
  {
    tex->SetInternalFormat(GL_RGBA32F);
    tex->SetFormat(GL_RGBA);
    tex->SetDataType(GL_FLOAT);
  }
  this->ListPositions->Create2DFromRaw(listWidth, listHeight, 4, VTK_FLOAT, positions.data());
  this->ListNormals->Create2DFromRaw(listWidth, listHeight, 4, VTK_FLOAT, normals.data());
  this->ListVisibility->SetInternalFormat(GL_R32F);
  this->ListVisibility->SetFormat(GL_RED);
  this->ListVisibility->SetDataType(GL_FLOAT);
  this->ListVisibility->Allocate2D(listWidth, listHeight, 1, VTK_FLOAT);

  vtkOpenGLQuadHelper& quad = *this->LookupPrograms.Get(win, nullptr,
    ComposeShader(vtkPenumbraShadowMapLookupFS), this->Variant(self, setup, true, &m));
  win->GetShaderCache()->ReadyShaderProgram(quad.Program);
  vtkShaderProgram* program = quad.Program;
  if (!program || !program->GetCompiled())
  {
    error = "the shadow map lookup program does not compile or link on this OpenGL "
            "implementation (texelFetch of depth textures is required)";
    return false;
  }
  std::vector<float>& result = this->ListResult;
  result.assign(static_cast<size_t>(listWidth) * listHeight, 1.0f);
  {
    vtkOpenGLState* ostate = win->GetState();
    vtkOpenGLState::ScopedglClearColor clearColor(ostate);
    penumbra_gl::QuadPassState pass(
      ostate, this->LookupFBO, { this->ListVisibility.Get() }, listWidth, listHeight);
    ostate->vtkglClearColor(1.0, 1.0, 1.0, 1.0);
    ostate->vtkglClear(GL_COLOR_BUFFER_BIT);

    this->ListPositions->Activate();
    this->ListNormals->Activate();
    program->SetUniformi("samplePositions", this->ListPositions->GetTextureUnit());
    program->SetUniformi("sampleNormals", this->ListNormals->GetTextureUnit());
    program->SetUniformi("sampleCount", static_cast<int>(count));
    program->SetUniformi("listWidth", listWidth);
    this->SetCompareUniforms(self, program, setup, m);
    for (size_t slot = 0; slot < m.Textures.size(); ++slot)
    {
      vtkTextureObject* map = m.Textures[slot];
      if (!map)
      {
        continue; // no pending sample falls into this slot
      }
      SetSlotUniforms(program, m, static_cast<int>(slot));
      RawDepthBinding raw(win, this->RawDepthSampler, map);
      program->SetUniformi("depthMap", raw.GetUnit());
      quad.Render();
    }
    this->ListPositions->Deactivate();
    this->ListNormals->Deactivate();
    this->LookupFBO->ActivateReadBuffer(0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, listWidth, listHeight, GL_RED, GL_FLOAT, result.data());
  }
  for (vtkIdType i = 0; i < count; ++i)
  {
    vis[list[static_cast<size_t>(i)]] = result[static_cast<size_t>(i)];
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkPenumbraShadowMapShadows::Internals::LookupCPU(vtkPenumbraShadowMapShadows* self,
  const penumbra_light_views::FrameInputs& in, const LightSetup& setup, const LightMaps& m,
  const unsigned char* state, float* vis)
{
  const vtkIdType n = in.NumberOfSamples;
  const float* nrm = in.Normals;
  const int width = m.Width, height = m.Height;
  const int slotMode = this->SlotMode(self, setup);
  const int radius = TapRadius(self);
  const bool bilinear = self->Filter == FILTER_BILINEAR;
  const double slopeBias = self->SlopeBias * (1.0 + BiasRadius(self));
  const double constantBias = self->Bias;
  // ---- Per-sample lookup on the CPU, double precision (see the class description).
  vtkSMPTools::For(0, n,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType s = begin; s < end; ++s)
      {
        if (state[s] != Pending)
        {
          continue;
        }
        double p[3];
        SamplePoint(in, s, p);
        const int slot = SlotOf(setup, slotMode, p);
        const std::vector<float>& map = m.Maps[static_cast<size_t>(slot)];
        if (map.empty())
        {
          continue; // cannot happen: every pending sample's slot was rendered
        }
        double ms = 0.0, mt = 0.0, depth = 0.0, footprint = 0.0, depthPerLength = 1.0;
        double toLight[3] = { 0, 0, 0 };
        if (m.Paraboloid)
        {
          double q[3] = { p[0] - m.Centre[0], p[1] - m.Centre[1], p[2] - m.Centre[2] };
          const double distance = Norm3(q);
          if (!(distance > 0.0))
          {
            continue;
          }
          for (int c = 0; c < 3; ++c)
          {
            q[c] /= distance;
            toLight[c] = -q[c];
          }
          double xy[2];
          ParaboloidFromDirection(q, xy);
          ms = xy[0] * m.MapScale;
          mt = xy[1] * m.MapScale;
          depth = distance / m.Far;
          depthPerLength = 1.0 / m.Far;
          // d(angle)/d(radius) = 2 / (1 + r^2) on the paraboloid.
          footprint =
            distance * 2.0 / (1.0 + xy[0] * xy[0] + xy[1] * xy[1]) * 2.0 / (width * m.MapScale);
        }
        else
        {
          const View& view = m.Views[static_cast<size_t>(slot)];
          if (!view.Project(p, ms, mt, depth))
          {
            continue;
          }
          if (view.Perspective)
          {
            depthPerLength = 1.0 / view.Far;
            footprint = 2.0 * view.TanHalf * depth * view.Far / std::min(width, height);
            for (int c = 0; c < 3; ++c)
            {
              toLight[c] = setup.Position[c] - p[c];
            }
          }
          else
          {
            depthPerLength = Norm3(view.Row[2]);
            footprint = OrthoFootprint(view, m);
            std::copy(setup.Direction, setup.Direction + 3, toLight);
          }
        }
        double normal[3] = { nrm[3 * s], nrm[3 * s + 1], nrm[3 * s + 2] };
        vtkMath::Normalize(normal);
        vtkMath::Normalize(toLight);
        const double cosine = std::max(1e-9, vtkMath::Dot(normal, toLight));
        const double tangent =
          std::min(MaxTangent, std::sqrt(std::max(0.0, 1.0 - cosine * cosine)) / cosine);
        const double threshold =
          depth - constantBias - slopeBias * footprint * tangent * depthPerLength;
        if (bilinear)
        {
          vis[s] = static_cast<float>(BilinearLookup(map, width, height, ms, mt, threshold));
          continue;
        }
        const int ix =
          std::min(width - 1, std::max(0, static_cast<int>(std::floor((ms * 0.5 + 0.5) * width))));
        const int iy = std::min(
          height - 1, std::max(0, static_cast<int>(std::floor((mt * 0.5 + 0.5) * height))));
        int litTaps = 0, taps = 0;
        for (int dy = -radius; dy <= radius; ++dy)
        {
          // PCF stays inside the map: it never reads across a cube face or paraboloid rim.
          const int y = std::min(height - 1, std::max(0, iy + dy));
          for (int dx = -radius; dx <= radius; ++dx)
          {
            const int x = std::min(width - 1, std::max(0, ix + dx));
            litTaps += map[static_cast<size_t>(y) * width + x] >= threshold;
            ++taps;
          }
        }
        vis[s] = static_cast<float>(litTaps) / static_cast<float>(taps);
      }
    });
}

//------------------------------------------------------------------------------
// The uniforms every slot shares (vtkPenumbraShadowMapCompare.glsl).
void vtkPenumbraShadowMapShadows::Internals::SetCompareUniforms(vtkPenumbraShadowMapShadows* self,
  vtkShaderProgram* program, const LightSetup& setup, const LightMaps& m, const std::string& suffix)
{
  auto name = [&suffix](const char* base) { return base + suffix; };
  penumbra_light_views::SetLightUniforms(program, setup, suffix);
  program->SetUniformf(name("mapScale").c_str(), static_cast<float>(m.MapScale));
  const float mapSize[2] = { static_cast<float>(m.Width), static_cast<float>(m.Height) };
  program->SetUniform2f(name("mapSize").c_str(), mapSize);
  program->SetUniformf(name("constantBias").c_str(), static_cast<float>(self->Bias));
  program->SetUniformf(
    name("slopeBias").c_str(), static_cast<float>(self->SlopeBias * (1.0 + BiasRadius(self))));
  program->SetUniformf(name("maxTangent").c_str(), static_cast<float>(MaxTangent));
  this->SetSoftUniforms(self, program, m);
}

//------------------------------------------------------------------------------
// The soft lookups' uniforms (vtkPenumbraShadowMapSoft.glsl): the taps, the search depth,
// the tap radius in NDC and the single-sample mode's radii. The light's extents are set by
// SetAreaUniforms().
void vtkPenumbraShadowMapShadows::Internals::SetSoftUniforms(
  vtkPenumbraShadowMapShadows* self, vtkShaderProgram* program, const LightMaps& m)
{
  if (SoftMode(self, m) == AREA_NONE)
  {
    return;
  }
  program->SetUniformi("searchTaps", self->SearchTaps);
  program->SetUniformi("filterTaps", self->FilterTaps);
  program->SetUniformf("searchDepth", static_cast<float>(self->SearchDepth));
  const int side = std::max(1, std::min(m.Width, m.Height));
  program->SetUniformf("maxRadius", static_cast<float>(2.0 * self->MaxRadius / side));
  program->SetUniformi("physical", self->Physical ? 1 : 0);
  const float radii[3] = { static_cast<float>(self->RScale), static_cast<float>(self->RBias),
    static_cast<float>(self->RShrink) };
  program->SetUniform3f("thesisRadius", radii);
}

//------------------------------------------------------------------------------
// An area light's centre and half extents (vtkPenumbraShadowMapSoft.glsl), also when no map
// is read: the horizon term applies to samples without casters too.
void vtkPenumbraShadowMapShadows::Internals::SetAreaUniforms(
  vtkShaderProgram* program, const LightSetup& setup)
{
  if (!setup.Area)
  {
    return;
  }
  penumbra_light_views::SetLightUniforms(program, setup);
  float hu[3], hv[3];
  for (int c = 0; c < 3; ++c)
  {
    hu[c] = static_cast<float>(setup.HalfU[c]);
    hv[c] = static_cast<float>(setup.HalfV[c]);
  }
  program->SetUniform3f("lightU", hu);
  program->SetUniform3f("lightV", hv);
}

//------------------------------------------------------------------------------
// The GPU lookup of a light with one map (directional and spot lights), made by the
// receivers' own fragment shaders while they are shaded (vtkPenumbraShadowMapReceive.glsl),
// as VTK's vtkShadowMapPass does: no full-screen pass, no visibility texture. LookupFrame()
// writes the same values from the G-buffer when they are asked for.
std::shared_ptr<vtkPenumbraFrame::ShaderLookup>
vtkPenumbraShadowMapShadows::Internals::ShaderLookup(
  vtkPenumbraShadowMapShadows* self, const LightSetup& setup, const LightMaps& maps)
{
  class MapLookup : public vtkPenumbraFrame::ShaderLookup
  {
  public:
    vtkSmartPointer<vtkPenumbraShadowMapShadows> Self;
    Internals* Impl = nullptr;
    LightSetup Setup;
    vtkWeakPointer<vtkLight> Light;
    LookupVariant Variant;
    std::unique_ptr<RawDepthBinding> Raw; // between Activate() and Deactivate()

    // The light's cache entry while it still holds this light's map.
    const LightMaps* Maps() const
    {
      for (const LightMaps& m : this->Impl->Cache)
      {
        if (this->Light && m.Light == this->Light && m.Valid && !m.Textures.empty() &&
          m.Textures[0])
        {
          return &m;
        }
      }
      return nullptr;
    }
    std::string GetKey() override { return this->Variant.Key(); }
    std::string GetSource(const std::string& suffix) override
    {
      return penumbra_light_views::SuffixGlobals(
        this->Variant.Specialize(ComposeShader(vtkPenumbraShadowMapReceive)), suffix);
    }
    void Activate() override
    {
      const LightMaps* m = this->Maps();
      if (m && this->Impl->Window)
      {
        this->Raw.reset(
          new RawDepthBinding(this->Impl->Window, this->Impl->RawDepthSampler, m->Textures[0]));
      }
    }
    void Deactivate() override { this->Raw.reset(); }
    void SetUniforms(vtkShaderProgram* program, const std::string& suffix) override
    {
      const LightMaps* m = this->Maps();
      if (!m)
      {
        return;
      }
      penumbra_light_views::SetClassifyUniforms(program, this->Setup, suffix);
      this->Impl->SetCompareUniforms(this->Self, program, this->Setup, *m, suffix);
      SetSlotUniforms(program, *m, 0, suffix);
      if (this->Raw)
      {
        program->SetUniformi(("depthMap" + suffix).c_str(), this->Raw->GetUnit());
      }
    }
    bool Resolve(vtkPenumbraFrame* frame, std::string& error) override
    {
      const LightMaps* m = this->Maps();
      if (!m)
      {
        error = "its shadow map was released";
        return false;
      }
      return this->Impl->LookupFrame(this->Self, frame, 0, this->Setup, true, m, error);
    }
  };
  auto lookup = std::make_shared<MapLookup>();
  lookup->Self = self;
  lookup->Impl = this;
  lookup->Setup = setup;
  lookup->Light = maps.Light;
  lookup->Variant = this->Variant(self, setup, true, &maps);
  return lookup;
}

//------------------------------------------------------------------------------
// The lookup on every layer's G-buffer, into light k's visibility channel: one draw per
// rendered slot (the first also writes the samples the facing rules decide), or one draw
// without a map when nothing is pending.
bool vtkPenumbraShadowMapShadows::Internals::LookupFrame(vtkPenumbraShadowMapShadows* self,
  vtkPenumbraFrame* frame, int k, const LightSetup& setup, bool anyCaster, const LightMaps* maps,
  std::string& error)
{
  vtkOpenGLRenderWindow* win = frame->GetWindow();
  vtkOpenGLQuadHelper* quad = this->FramePrograms.Get(win, vtkPenumbraFrame::GetSurfaceQuadVS(),
    ComposeShader(vtkPenumbraShadowMapFrameFS), this->Variant(self, setup, anyCaster, maps));
  if (!this->NoMap)
  {
    // The depth sampler must never share a unit with the G-buffer's samplers, even when
    // no map is read: a 1 x 1 stand-in is bound when there is none.
    this->NoMap = Internals::CompareTexture(win, 1, 1);
  }
  vtkShaderProgram* program = quad->Program;
  if (!program || !program->GetCompiled())
  {
    error = "the shadow map lookup program does not compile on this OpenGL implementation "
            "(texelFetch of depth textures and GL_ARB_gpu_shader_fp64 are required)";
    return false;
  }
  std::vector<int> slots;
  for (size_t slot = 0; maps && slot < maps->Textures.size(); ++slot)
  {
    if (maps->Textures[slot])
    {
      slots.push_back(static_cast<int>(slot));
    }
  }
  // Soft lookups with adaptive sampling: the block corners first.
  const int block = maps && SoftMode(self, *maps) != AREA_NONE ? self->AdaptiveBlock : 1;
  for (int layer = 0; layer < frame->GetNumberOfLayers(); ++layer)
  {
    if (block > 1)
    {
      const int cw = (frame->GetWidth() - 1) / block + 2;
      const int ch = (frame->GetHeight() - 1) / block + 2;
      if (!this->CoarseValues)
      {
        this->CoarseFBO = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
        this->CoarseFBO->SetContext(win);
        this->CoarseValues = Internals::FloatTexture(win);
        this->CoarseValues->SetInternalFormat(GL_RGBA32F);
        this->CoarseValues->SetFormat(GL_RGBA);
        this->CoarseValues->SetDataType(GL_FLOAT);
      }
      if (static_cast<int>(this->CoarseValues->GetWidth()) != cw ||
        static_cast<int>(this->CoarseValues->GetHeight()) != ch)
      {
        this->CoarseValues->Allocate2D(cw, ch, 4, VTK_FLOAT);
      }
      penumbra_gl::QuadPassState pass(
        win->GetState(), this->CoarseFBO, { this->CoarseValues.Get() }, cw, ch);
      this->DrawLookup(self, frame, layer, setup, maps, slots, quad, 1, block);
    }
    vtkPenumbraFrame::VisibilityTarget target = frame->BindVisibilityTarget(layer, k);
    if (block > 1)
    {
      this->CoarseValues->Activate();
      win->GetShaderCache()->ReadyShaderProgram(program);
      program->SetUniformi("coarseValues", this->CoarseValues->GetTextureUnit());
    }
    this->DrawLookup(self, frame, layer, setup, maps, slots, quad, block > 1 ? 2 : 0, block);
    if (block > 1)
    {
      this->CoarseValues->Deactivate();
    }
  }
  return true;
}

//------------------------------------------------------------------------------
// One lookup draw per rendered slot on one layer's G-buffer into the bound target (the
// first also writes the samples the facing rules decide); `adaptivePass` as in
// vtkPenumbraShadowMapSoft.glsl.
void vtkPenumbraShadowMapShadows::Internals::DrawLookup(vtkPenumbraShadowMapShadows* self,
  vtkPenumbraFrame* frame, int layer, const LightSetup& setup, const LightMaps* maps,
  const std::vector<int>& slots, vtkOpenGLQuadHelper* quad, int adaptivePass, int block)
{
  vtkOpenGLRenderWindow* win = frame->GetWindow();
  vtkShaderProgram* program = quad->Program;
  vtkPenumbraViewSamplesPass* gbuffer = frame->GetLayer(layer);
  win->GetShaderCache()->ReadyShaderProgram(program);
  gbuffer->GetPositionTexture()->Activate();
  gbuffer->GetNormalTexture()->Activate();
  program->SetUniformi("samplePositions", gbuffer->GetPositionTexture()->GetTextureUnit());
  program->SetUniformi("sampleNormals", gbuffer->GetNormalTexture()->GetTextureUnit());
  program->SetUniformi("adaptivePass", adaptivePass);
  program->SetUniformi("adaptiveBlock", block);
  const int image[2] = { frame->GetWidth(), frame->GetHeight() };
  program->SetUniform2i("adaptiveImage", image);
  penumbra_light_views::SetClassifyUniforms(program, setup);
  if (maps)
  {
    this->SetCompareUniforms(self, program, setup, *maps);
  }
  this->SetAreaUniforms(program, setup);
  for (size_t i = 0; i < std::max<size_t>(1, slots.size()); ++i)
  {
    vtkTextureObject* map =
      slots.empty() ? this->NoMap.Get() : maps->Textures[static_cast<size_t>(slots[i])].Get();
    program->SetUniformi("writeDecided", i == 0 ? 1 : 0);
    if (slots.empty())
    {
      program->SetUniformi("slot", -1);
    }
    else
    {
      SetSlotUniforms(program, *maps, slots[i]);
    }
    RawDepthBinding raw(win, this->RawDepthSampler, map);
    program->SetUniformi("depthMap", raw.GetUnit());
    quad->Render();
  }
  gbuffer->GetPositionTexture()->Deactivate();
  gbuffer->GetNormalTexture()->Deactivate();
}
