// Rendering a shadow-mapped light's depth maps: the map programs, the casters (paraboloid
// ones clipped and tessellated per hemisphere), the slots and the midpoint layer.
#include "vtkPenumbraShadowMapShadowsInternals.h"

#include "vtkPenumbraGLPassState.h"
#include "vtkPenumbraShadowMapFS.h"
#include "vtkPenumbraShadowMapMidpointFS.h"
#include "vtkPenumbraShadowMapParaboloidFS.h"
#include "vtkPenumbraShadowMapParaboloidVS.h"
#include "vtkPenumbraShadowMapVS.h"

namespace
{
// Paraboloid tessellation (Brabec, "Shadow Techniques for Interactive and Real-Time
// Applications", PhD thesis, 2003, ch. 6, "tessellated fine enough"): no sub-edge spans more
// than this angle seen from the light, up to MaxSubdivisions per triangle edge. A 2-degree
// chord deviates from its arc by 1.5e-4 of the map radius: 0.15 texel at 2048^2.
constexpr double ParaboloidStepRadians = 2.0 * 3.14159265358979323846 / 180.0;
constexpr int MaxSubdivisions = 32;
}
//------------------------------------------------------------------------------
// The map program for a light: paraboloid, or perspective/orthographic; orthographic views
// with linear depth store clip z as it is (linear already), the others write the linear
// depth per fragment. Null when it does not compile.
vtkShaderProgram* vtkPenumbraShadowMapShadows::Internals::MapProgram(
  vtkPenumbraShadowMapShadows* self, vtkOpenGLRenderWindow* win, const LightSetup& setup,
  bool paraboloid)
{
  const bool hardwareDepth =
    setup.Type == LightSetup::Kind::Directional && self->DepthMode == DEPTH_LINEAR;
  auto variant = [hardwareDepth](const char* source)
  {
    std::string text = source;
    if (hardwareDepth)
    {
      vtkShaderProgram::Substitute(
        text, "//VTK::System::Dec", "//VTK::System::Dec\n#define PENUMBRA_HARDWARE_DEPTH\n", false);
    }
    return text;
  };
  vtkShaderProgram* program = paraboloid
    ? win->GetShaderCache()->ReadyShaderProgram(
        vtkPenumbraShadowMapParaboloidVS, vtkPenumbraShadowMapParaboloidFS, "")
    : win->GetShaderCache()->ReadyShaderProgram(
        variant(vtkPenumbraShadowMapVS).c_str(), variant(vtkPenumbraShadowMapFS).c_str(), "");
  return program && program->GetCompiled() ? program : nullptr;
}

//------------------------------------------------------------------------------
// Binds the casters to the map program: the paraboloid casters (clipped and tessellated per
// hemisphere, rebuilt when the light or the casters change) or the uploaded caster vertices,
// with the uniforms every slot shares.
void vtkPenumbraShadowMapShadows::Internals::BindCasters(vtkPenumbraShadowMapShadows* self,
  vtkShaderProgram* program, vtkPenumbraSceneGeometry* geometry, const LightSetup& setup,
  const LightMaps& maps)
{
  if (maps.Paraboloid)
  {
    std::vector<double> paraboloidKey = { setup.Position[0], setup.Position[1], setup.Position[2],
      static_cast<double>(geometry->GetCastersTime()) };
    if (paraboloidKey != this->ParaboloidKey || !this->ParaboloidArray)
    {
      this->BuildParaboloidCasters(setup.Position);
      this->ParaboloidKey = paraboloidKey;
    }
    const float mapSize[2] = { static_cast<float>(maps.Width), static_cast<float>(maps.Height) };
    program->SetUniformf("mapScale", static_cast<float>(maps.MapScale));
    program->SetUniformf("invMapScale", static_cast<float>(1.0 / maps.MapScale));
    program->SetUniformf("invFar", static_cast<float>(1.0 / maps.Far));
    program->SetUniform2f("mapSize", mapSize);
    glBindVertexArray(this->ParaboloidArray);
  }
  else
  {
    this->Casters.Bind(program);
  }
  program->SetUniformf("peelGap", static_cast<float>(std::max(self->Bias, 1e-6)));
}

//------------------------------------------------------------------------------
// Points the map program at one slot: the slot's paraboloid hemisphere buffer, or its view's
// matrix. Returns the number of vertices to draw.
GLsizei vtkPenumbraShadowMapShadows::Internals::BindSlot(
  vtkShaderProgram* program, const LightMaps& maps, int slot)
{
  // The midpoint pass draws with its own vertex array.
  glBindVertexArray(maps.Paraboloid ? this->ParaboloidArray : this->Casters.VertexArray);
  if (!maps.Paraboloid)
  {
    const View& view = maps.Views[static_cast<size_t>(slot)];
    float matrix[16];
    view.ToFloatMatrix(matrix);
    program->SetUniformMatrix4x4("lightMatrix", matrix);
    program->SetUniformi("perspective", view.Perspective ? 1 : 0);
    program->SetUniformf("invFar", static_cast<float>(1.0 / view.Far));
    return this->Casters.VertexCount;
  }
  const GLint posLoc = glGetAttribLocation(program->GetHandle(), "vertexLight");
  const GLint planeLoc = glGetAttribLocation(program->GetHandle(), "trianglePlane");
  glBindBuffer(GL_ARRAY_BUFFER, this->ParaboloidBuffers[slot]);
  const GLsizei stride = 7 * sizeof(float);
  if (posLoc >= 0)
  {
    glEnableVertexAttribArray(static_cast<GLuint>(posLoc));
    glVertexAttribPointer(static_cast<GLuint>(posLoc), 3, GL_FLOAT, GL_FALSE, stride, nullptr);
  }
  if (planeLoc >= 0)
  {
    glEnableVertexAttribArray(static_cast<GLuint>(planeLoc));
    glVertexAttribPointer(static_cast<GLuint>(planeLoc), 4, GL_FLOAT, GL_FALSE, stride,
      reinterpret_cast<const void*>(3 * sizeof(float)));
  }
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  return this->ParaboloidCounts[slot];
}

//------------------------------------------------------------------------------
// Draws one slot's depth layers (the second, depth-peeled, for midpoint maps): with the GPU
// lookup and linear depth straight into the slot's compare texture, otherwise into the
// scratch layers, read back for the CPU lookup.
void vtkPenumbraShadowMapShadows::Internals::DrawSlotLayers(vtkPenumbraShadowMapShadows* self,
  vtkOpenGLState* ostate, vtkShaderProgram* program, GLsizei count, vtkTextureObject* slotTexture,
  LightMaps* maps, int slot)
{
  const bool gpuLookup = self->Lookup != LOOKUP_CPU;
  const bool midpoint = self->DepthMode == DEPTH_MIDPOINT;
  const size_t texels = static_cast<size_t>(maps->Width) * maps->Height;
  std::vector<float>& map = maps->Maps[static_cast<size_t>(slot)];
  map.resize(gpuLookup ? 0 : texels);
  for (int layer = 0; layer < (midpoint ? 2 : 1); ++layer)
  {
    this->FBO->AddDepthAttachment(
      gpuLookup && !midpoint ? slotTexture : this->DepthTextures[layer].Get());
    ostate->vtkglDrawBuffer(GL_NONE);
    ostate->vtkglReadBuffer(GL_NONE);
    const GLfloat one = 1.0f;
    glClearBufferfv(GL_DEPTH, 0, &one);
    program->SetUniformi("peel", layer);
    if (layer == 1)
    {
      this->DepthTextures[0]->Activate();
      program->SetUniformi("firstLayer", this->DepthTextures[0]->GetTextureUnit());
    }
    if (count > 0 && maps->Paraboloid)
    {
      glDrawArrays(GL_TRIANGLES, 0, count);
    }
    else if (count > 0)
    {
      this->Casters.Draw();
    }
    if (layer == 1)
    {
      this->DepthTextures[0]->Deactivate();
    }
    if (gpuLookup)
    {
      continue; // the maps stay on the GPU
    }
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    float* target = map.data();
    if (layer == 1)
    {
      this->SecondLayer.resize(texels);
      target = this->SecondLayer.data();
    }
    glReadPixels(0, 0, maps->Width, maps->Height, GL_DEPTH_COMPONENT, GL_FLOAT, target);
  }
}

//------------------------------------------------------------------------------
// Woo's midpoint (Brabec 2003, ch. 4.1.1) of a slot's two layers: on the GPU written as the
// slot's depth, on the CPU into its map. No second surface leaves the far value 1 as the
// second depth, so a lone surface stays lit by a half-range margin.
void vtkPenumbraShadowMapShadows::Internals::ResolveMidpoint(vtkPenumbraShadowMapShadows* self,
  vtkOpenGLRenderWindow* win, vtkShaderProgram* program, vtkTextureObject* slotTexture,
  LightMaps* maps, int slot)
{
  if (self->Lookup != LOOKUP_CPU)
  {
    vtkOpenGLQuadHelper& quad = *this->MidpointQuad;
    vtkOpenGLState* ostate = win->GetState();
    win->GetShaderCache()->ReadyShaderProgram(quad.Program);
    this->FBO->AddDepthAttachment(slotTexture);
    ostate->vtkglDepthFunc(GL_ALWAYS);
    this->DepthTextures[0]->Activate();
    this->DepthTextures[1]->Activate();
    quad.Program->SetUniformi("firstLayer", this->DepthTextures[0]->GetTextureUnit());
    quad.Program->SetUniformi("secondLayer", this->DepthTextures[1]->GetTextureUnit());
    quad.Render();
    this->DepthTextures[0]->Deactivate();
    this->DepthTextures[1]->Deactivate();
    ostate->vtkglDepthFunc(GL_LESS);
    // The map program is current again for the next slot.
    win->GetShaderCache()->ReadyShaderProgram(program);
    return;
  }
  std::vector<float>& map = maps->Maps[static_cast<size_t>(slot)];
  const float* second = this->SecondLayer.data();
  vtkSMPTools::For(0, static_cast<vtkIdType>(map.size()),
    [&](vtkIdType b, vtkIdType e)
    {
      for (vtkIdType i = b; i < e; ++i)
      {
        map[static_cast<size_t>(i)] = 0.5f * (map[static_cast<size_t>(i)] + second[i]);
      }
    });
}

//------------------------------------------------------------------------------
// A distributed frame's slot (every process drew its own casters into the same view): per
// texel the nearest depth over the processes, and for midpoint maps the nearest behind it
// (Brabec 2003, ch. 4.1.1, over the union of the casters). The second layer of a process
// whose first surface is the nearest overall is its next surface; any other process's first
// surface is a candidate too, so it is the minimum of those. Two minimum reductions of a
// map's texels, whatever the number of triangles. On the GPU the layers are read back from
// and written into their textures; on the CPU they are the slot's map and the second layer.
void vtkPenumbraShadowMapShadows::Internals::CompositeSlot(vtkPenumbraShadowMapShadows* self,
  vtkPenumbraRemoteShadows* processes, vtkTextureObject* slotTexture, LightMaps* maps, int slot)
{
  const bool gpuLookup = self->Lookup != LOOKUP_CPU;
  const bool midpoint = self->DepthMode == DEPTH_MIDPOINT;
  const size_t texels = static_cast<size_t>(maps->Width) * maps->Height;
  const int layers = midpoint ? 2 : 1;
  std::vector<float>& map = maps->Maps[static_cast<size_t>(slot)];
  // The layers, and for midpoint maps this process's own first layer.
  this->Composited.resize(static_cast<size_t>(midpoint ? 3 : 1) * texels);
  float* first = this->Composited.data();
  float* second = first + texels;
  float* own = second + texels;
  // The GPU's layers: the slot's compare texture (linear depth) or the scratch layers.
  auto texture = [&](int layer)
  { return gpuLookup && !midpoint ? slotTexture : this->DepthTextures[layer].Get(); };
  for (int layer = 0; layer < layers; ++layer)
  {
    float* target = layer == 0 ? first : second;
    if (!gpuLookup)
    {
      const float* source = layer == 0 ? map.data() : this->SecondLayer.data();
      std::copy_n(source, texels, target);
      continue;
    }
    this->FBO->AddDepthAttachment(texture(layer));
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, maps->Width, maps->Height, GL_DEPTH_COMPONENT, GL_FLOAT, target);
  }
  if (midpoint)
  {
    std::copy_n(first, texels, own);
  }
  processes->ReduceMinimum(first, texels);
  if (midpoint)
  {
    vtkSMPTools::For(0, static_cast<vtkIdType>(texels),
      [&](vtkIdType b, vtkIdType e)
      {
        for (vtkIdType i = b; i < e; ++i)
        {
          second[i] = own[i] > first[i] ? own[i] : second[i];
        }
      });
    processes->ReduceMinimum(second, texels);
  }
  for (int layer = 0; layer < layers; ++layer)
  {
    const float* source = layer == 0 ? first : second;
    if (!gpuLookup)
    {
      std::copy_n(source, texels, layer == 0 ? map.data() : this->SecondLayer.data());
      continue;
    }
    vtkTextureObject* target = texture(layer);
    target->Activate();
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(
      GL_TEXTURE_2D, 0, 0, 0, maps->Width, maps->Height, GL_DEPTH_COMPONENT, GL_FLOAT, source);
    target->Deactivate();
  }
}

//------------------------------------------------------------------------------
// The compare texture a slot's map is drawn into for the GPU lookup: the slot's kept texture
// while its size still fits, a new one otherwise; null for the CPU lookup.
vtkTextureObject* vtkPenumbraShadowMapShadows::Internals::SlotTexture(
  vtkPenumbraShadowMapShadows* self, vtkOpenGLRenderWindow* win, LightMaps* maps, int slot)
{
  const bool gpuLookup = self->Lookup != LOOKUP_CPU;
  auto& kept = maps->Textures[static_cast<size_t>(slot)];
  if (kept &&
    (!gpuLookup || static_cast<int>(kept->GetWidth()) != maps->Width ||
      static_cast<int>(kept->GetHeight()) != maps->Height))
  {
    kept->ReleaseGraphicsResources(win);
    kept = nullptr;
  }
  if (gpuLookup && !kept)
  {
    kept = Internals::CompareTexture(win, maps->Width, maps->Height);
  }
  return kept;
}

//------------------------------------------------------------------------------
// Renders every slot a receiver needs (Brabec 2003, ch. 4-6) into the views PlanMaps()
// fitted: linear float depth, depth clamping, the midpoint layer on request; the maps stay on
// the GPU for the GPU lookup and are read back for the CPU one.
bool vtkPenumbraShadowMapShadows::Internals::RenderMaps(vtkPenumbraShadowMapShadows* self,
  vtkOpenGLRenderWindow* win, vtkPenumbraSceneGeometry* geometry,
  vtkPenumbraRemoteShadows* processes, const LightSetup& setup, const ReceiverExtent& extent,
  const int size[2], LightMaps* maps, std::string& error)
{
  const auto mapStart = Clock::now();
  const int slotMode = this->SlotMode(self, setup);
  const bool paraboloid = slotMode == SlotsParaboloid;
  const int slots = slotMode == SlotsCube ? 6 : (paraboloid ? 2 : 1);
  maps->Valid = false;
  maps->Width = size[0];
  maps->Height = size[1];
  maps->Paraboloid = paraboloid;
  maps->Maps.assign(static_cast<size_t>(slots), std::vector<float>());
  // GPU lookup: the slots' compare textures are kept and redrawn when their size still fits.
  for (size_t slot = static_cast<size_t>(slots); slot < maps->Textures.size(); ++slot)
  {
    if (maps->Textures[slot])
    {
      maps->Textures[slot]->ReleaseGraphicsResources(win);
    }
  }
  maps->Textures.resize(static_cast<size_t>(slots));
  vtkShaderProgram* program = this->MapProgram(self, win, setup, paraboloid);
  // Every process of a distributed frame draws, or none does (the maps are composited).
  const bool everywhere = processes ? processes->AllAgree(program != nullptr) : program != nullptr;
  if (!everywhere)
  {
    error = std::string("the shadow map shaders do not compile or link on ") +
      (program ? "another process" : "this OpenGL implementation");
    return false;
  }
  this->AllocateMaps(win, maps->Width, maps->Height);
  const bool midpoint = self->DepthMode == DEPTH_MIDPOINT;
  vtkOpenGLState* ostate = win->GetState();
  penumbra_gl::MapRenderState renderState(ostate, this->FBO, maps->Width, maps->Height, false);
  this->BindCasters(self, program, geometry, setup, *maps);
  if (self->Lookup == LOOKUP_GPU && midpoint && !this->MidpointQuad)
  {
    this->MidpointQuad.reset(
      new vtkOpenGLQuadHelper(win, nullptr, vtkPenumbraShadowMapMidpointFS, ""));
    // Building it bound its program; the map program draws next.
    win->GetShaderCache()->ReadyShaderProgram(program);
  }
  for (int slot = 0; slot < slots; ++slot)
  {
    auto& texture = maps->Textures[static_cast<size_t>(slot)];
    if (!extent.Used[static_cast<size_t>(slot)])
    {
      if (texture)
      {
        texture->ReleaseGraphicsResources(win);
        texture = nullptr;
      }
      continue;
    }
    const GLsizei count = this->BindSlot(program, *maps, slot);
    vtkTextureObject* slotTexture = this->SlotTexture(self, win, maps, slot);
    this->DrawSlotLayers(self, ostate, program, count, slotTexture, maps, slot);
    if (processes)
    {
      this->CompositeSlot(self, processes, slotTexture, maps, slot);
    }
    if (midpoint)
    {
      this->ResolveMidpoint(self, win, program, slotTexture, maps, slot);
    }
    ++self->NumberOfMapRenders;
  }
  maps->Valid = true;
  self->MapTimeMs = ElapsedMs(mapStart);
  return true;
}

//------------------------------------------------------------------------------
// Clips every caster against each hemisphere's equator plane (in light space, before the
// mapping, so that triangles straddling z = 0 do not map their far vertices near the
// singularity) and tessellates what is left (Brabec 2003, ch. 6).
void vtkPenumbraShadowMapShadows::Internals::BuildParaboloidCasters(const double centre[3])
{
  std::vector<float> data[2];
  for (size_t caster = 0; caster < this->Casters.TriangleIds.size(); ++caster)
  {
    float v[9];
    this->Casters.Float(caster, v);
    for (int h = 0; h < 2; ++h)
    {
      const double sign = h ? -1.0 : 1.0;
      double q[3][3];
      for (int k = 0; k < 3; ++k)
      {
        for (int c = 0; c < 3; ++c)
        {
          q[k][c] = static_cast<double>(v[3 * k + c]) - centre[c];
        }
        q[k][2] *= sign;
      }
      double e1[3], e2[3], n[3];
      for (int c = 0; c < 3; ++c)
      {
        e1[c] = q[1][c] - q[0][c];
        e2[c] = q[2][c] - q[0][c];
      }
      vtkMath::Cross(e1, e2, n);
      if (!(vtkMath::Normalize(n) > 0.0))
      {
        continue;
      }
      const double planeC = vtkMath::Dot(n, q[0]);
      // Sutherland-Hodgman against z >= 0.
      std::array<std::array<double, 3>, 4> poly;
      int count = 0;
      for (int k = 0; k < 3; ++k)
      {
        const double* a = q[k];
        const double* b = q[(k + 1) % 3];
        if (a[2] >= 0.0)
        {
          poly[count++] = { a[0], a[1], a[2] };
        }
        if ((a[2] >= 0.0) != (b[2] >= 0.0))
        {
          const double t = a[2] / (a[2] - b[2]);
          poly[count++] = { a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), 0.0 };
        }
      }
      for (int f = 1; f + 1 < count; ++f)
      {
        const double* corner[3] = { poly[0].data(), poly[f].data(), poly[f + 1].data() };
        double widest = 0.0;
        for (int k = 0; k < 3; ++k)
        {
          const double* a = corner[k];
          const double* b = corner[(k + 1) % 3];
          const double la = Norm3(a), lb = Norm3(b);
          if (la > 0.0 && lb > 0.0)
          {
            const double cosine = std::max(-1.0, std::min(1.0, vtkMath::Dot(a, b) / (la * lb)));
            widest = std::max(widest, std::acos(cosine));
          }
          else
          {
            widest = 3.2; // touches the light: as fine as allowed
          }
        }
        const int steps = std::max(1,
          std::min(MaxSubdivisions, static_cast<int>(std::ceil(widest / ParaboloidStepRadians))));
        auto emit = [&](int i, int j)
        {
          for (int c = 0; c < 3; ++c)
          {
            const double x = corner[0][c] + (corner[1][c] - corner[0][c]) * i / steps +
              (corner[2][c] - corner[0][c]) * j / steps;
            data[h].push_back(static_cast<float>(x));
          }
          for (int c = 0; c < 3; ++c)
          {
            data[h].push_back(static_cast<float>(n[c]));
          }
          data[h].push_back(static_cast<float>(planeC));
        };
        for (int j = 0; j < steps; ++j)
        {
          for (int i = 0; i + j < steps; ++i)
          {
            emit(i, j);
            emit(i + 1, j);
            emit(i, j + 1);
            if (i + j + 2 <= steps)
            {
              emit(i + 1, j);
              emit(i + 1, j + 1);
              emit(i, j + 1);
            }
          }
        }
      }
    }
  }
  if (!this->ParaboloidArray)
  {
    glGenVertexArrays(1, &this->ParaboloidArray);
    glGenBuffers(2, this->ParaboloidBuffers);
  }
  for (int h = 0; h < 2; ++h)
  {
    glBindBuffer(GL_ARRAY_BUFFER, this->ParaboloidBuffers[h]);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(data[h].size() * sizeof(float)),
      data[h].empty() ? nullptr : data[h].data(), GL_STATIC_DRAW);
    this->ParaboloidCounts[h] = static_cast<GLsizei>(data[h].size() / 7);
  }
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}
