// Resolution-matched shadow maps' pages (Lefohn et al. 2007, §3.2-3.3): the requests of the
// frame's samples, their refinement at shadow edges, the atlas's allocation and the page
// table.
#include "vtkPenumbraGLPassState.h"
#include "vtkPenumbraResolutionMatchedShadowsInternals.h"

namespace
{
// `targets` made 2 per layer and w x h: per layer the keys + 1 (`keyFormat`: GL_RGBA32F, four
// keys per pixel, or GL_R32F) and the levels (R32F).
void EnsureKeyTargets(vtkOpenGLRenderWindow* win,
  std::vector<vtkSmartPointer<vtkTextureObject>>& targets, size_t layers, int w, int h,
  int keyFormat)
{
  targets.resize(2 * layers);
  for (size_t t = 0; t < targets.size(); ++t)
  {
    auto& target = targets[t];
    const bool rgba = t % 2 == 0 && keyFormat == GL_RGBA32F;
    if (!target)
    {
      target = NearestTexture(win);
      target->SetInternalFormat(rgba ? GL_RGBA32F : GL_R32F);
      target->SetFormat(rgba ? GL_RGBA : GL_RED);
      target->SetDataType(GL_FLOAT);
    }
    if (static_cast<int>(target->GetWidth()) != w || static_cast<int>(target->GetHeight()) != h)
    {
      target->Allocate2D(w, h, rgba ? 4 : 1, VTK_FLOAT);
    }
  }
}
}
//------------------------------------------------------------------------------
// The light's page table: an R32I texture of PageTableSide^2 with PageTableMips levels.
bool vtkPenumbraResolutionMatchedShadows::Internals::EnsurePageTable(vtkOpenGLRenderWindow* win)
{
  LightPages& pages = *this->Cur;
  if (pages.PageTable)
  {
    return false;
  }
  glCreateTextures(GL_TEXTURE_2D, 1, &pages.PageTable);
  glTextureStorage2D(
    pages.PageTable, this->PageTableMips, GL_R32I, this->PageTableSide, this->PageTableSide);
  // Integer textures are complete only with nearest filtering.
  glTextureParameteri(pages.PageTable, GL_TEXTURE_MIN_FILTER, GL_NEAREST_MIPMAP_NEAREST);
  glTextureParameteri(pages.PageTable, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  // An alias (not owning the handle) that only binds it through VTK's texture units.
  pages.PageTableAlias = vtkSmartPointer<vtkTextureObject>::New();
  pages.PageTableAlias->SetContext(win);
  pages.PageTableAlias->SetAutoParameters(0);
  pages.PageTableAlias->AssignToExistingTexture(pages.PageTable, GL_TEXTURE_2D);
  pages.Key.clear(); // the table must be filled again
  return true;
}

//------------------------------------------------------------------------------
// Gives a light's atlas slots back to the free list: none of its pages is resident.
void vtkPenumbraResolutionMatchedShadows::Internals::GiveBack(LightPages& pages)
{
  for (int slot : pages.SlotOf)
  {
    if (slot >= 0)
    {
      this->FreeSlots.push_back(slot);
    }
  }
  pages.SlotOf.clear();
}

//------------------------------------------------------------------------------
// Gives a light's slots back to the atlas and frees its GL objects (context current).
void vtkPenumbraResolutionMatchedShadows::Internals::ReleaseLight(LightPages& pages)
{
  this->GiveBack(pages);
  if (pages.PageTable)
  {
    glDeleteTextures(1, &pages.PageTable);
  }
  pages.PageTable = 0;
  pages.PageTableAlias = nullptr;
  for (auto* targets : { &pages.RequestTargets, &pages.RefineTargets })
  {
    for (auto& tex : *targets)
    {
      tex->ReleaseGraphicsResources(this->Window);
    }
    targets->clear();
  }
  pages.Key.clear();
}

//------------------------------------------------------------------------------
// Gives every page of `pages` back to the atlas; the whole base level is then made resident
// again (Allocate()). When the atlas cannot hold that base level, the other lights' pages
// are dropped too (they rebuild when their turn comes).
void vtkPenumbraResolutionMatchedShadows::Internals::Flush(LightPages& pages)
{
  this->GiveBack(pages);
  pages.SlotOf.assign(static_cast<size_t>(this->Levels.Size()), -1);
  const size_t base = static_cast<size_t>(this->Levels.Offset(this->Levels.Base + 1));
  for (LightPages& other : this->Lights)
  {
    if (this->FreeSlots.size() < base && &other != &pages)
    {
      this->GiveBack(other);
      other.Key.clear();
    }
  }
  // Slots popped from the back in ascending order: pages allocated one after another (row by
  // row) then sit side by side in the atlas, and their copies merge (CopyPages()).
  std::sort(this->FreeSlots.begin(), this->FreeSlots.end(), std::greater<int>());
  pages.Table.assign(pages.SlotOf.size(), 0);
  pages.TableDirty = true;
  pages.FullTable = true;
  pages.Changed.clear();
}

//------------------------------------------------------------------------------
// One full-screen pass per layer of the frame into that layer's two `targets` (keys + 1 and
// levels, w x h), each layer's keys read back into `keys` (`channels` per pixel, layer after
// layer). `bind` binds the layer's inputs and sets the program's uniforms, `unbind` releases
// them.
bool vtkPenumbraResolutionMatchedShadows::Internals::KeyPass(vtkPenumbraFrame* frame,
  vtkOpenGLQuadHelper* quad, std::vector<vtkSmartPointer<vtkTextureObject>>& targets, int w, int h,
  int channels, std::vector<float>& keys, const std::function<void(int, vtkShaderProgram*)>& bind,
  const std::function<void(int)>& unbind)
{
  vtkOpenGLRenderWindow* win = frame->GetWindow();
  const size_t perLayer = static_cast<size_t>(w) * h * channels;
  keys.resize(perLayer * static_cast<size_t>(frame->GetNumberOfLayers()));
  vtkShaderProgram* program = quad->Program;
  for (int layer = 0; layer < frame->GetNumberOfLayers(); ++layer)
  {
    vtkPenumbraViewSamplesPass* gbuffer = frame->GetLayer(layer);
    // At full size the G-buffer's depth test leaves the background out (see
    // vtkPenumbraFrame::BindVisibilityTarget()); its keys and levels are cleared to 0.
    const bool full = w == frame->GetWidth() && h == frame->GetHeight();
    penumbra_gl::QuadPassState pass(win->GetState(), this->RequestFBO,
      { targets[2 * layer].Get(), targets[2 * layer + 1].Get() }, w, h,
      full ? gbuffer->GetDepthTexture() : nullptr);
    if (full)
    {
      const GLfloat zero[4] = { 0.0f, 0.0f, 0.0f, 0.0f };
      glClearBufferfv(GL_COLOR, 0, zero);
      glClearBufferfv(GL_COLOR, 1, zero);
    }
    win->GetShaderCache()->ReadyShaderProgram(program);
    gbuffer->GetPositionTexture()->Activate();
    gbuffer->GetNormalTexture()->Activate();
    bind(layer, program);
    quad->Render();
    unbind(layer);
    gbuffer->GetPositionTexture()->Deactivate();
    gbuffer->GetNormalTexture()->Deactivate();
    this->RequestFBO->ActivateReadBuffer(0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, w, h, channels == 4 ? GL_RGBA : GL_RED, GL_FLOAT,
      keys.data() + perLayer * static_cast<size_t>(layer));
  }
  return true;
}

//------------------------------------------------------------------------------
// The read-back `keys` (key + 1 per pixel, 0: none) marked in one byte per page of the
// pyramid and appended to the requested keys (Lefohn et al. 2007's connected components,
// compaction and sort, §3.2, on the CPU); false when a key lies outside the table.
bool vtkPenumbraResolutionMatchedShadows::Internals::MarkRequests(
  const std::vector<float>& keys, std::string& error)
{
  const long long size = static_cast<long long>(this->Cur->Requested.size());
  bool outside = false;
  for (float value : keys)
  {
    const long long key = static_cast<long long>(value) - 1;
    outside = outside || key >= size;
    if (key < 0 || key >= size)
    {
      continue;
    }
    if (!this->Cur->Requested[static_cast<size_t>(key)])
    {
      this->Cur->Requested[static_cast<size_t>(key)] = 1;
      this->Cur->RequestedKeys.push_back(key);
    }
  }
  if (outside)
  {
    error = "a page request lies outside the page table";
  }
  return !outside;
}

//------------------------------------------------------------------------------
// Lefohn et al. 2007, §3.3.2 (Algorithm 2, steps 1-8): every layer's pending samples write
// the key of the page they need; the keys are read back and de-duplicated with one byte per
// page (the paper's connected components, compaction and sort serve a GPU that cannot
// afford the read-back of every request; on llvmpipe it costs a copy in host memory).
bool vtkPenumbraResolutionMatchedShadows::Internals::Request(
  vtkPenumbraResolutionMatchedShadows* self, vtkPenumbraFrame* frame, const LightSetup& setup,
  std::string& error)
{
  const auto start = Clock::now();
  const int step = self->AnalysisStep;
  const int w = (frame->GetWidth() + step - 1) / step, h = (frame->GetHeight() + step - 1) / step;
  this->Cur->RequestFrameSize[0] = frame->GetWidth();
  this->Cur->RequestFrameSize[1] = frame->GetHeight();
  this->Cur->RequestStep = step;
  const size_t layers = static_cast<size_t>(frame->GetNumberOfLayers());
  // Per layer the keys (RGBA: the block's samples) and the levels.
  EnsureKeyTargets(frame->GetWindow(), this->Cur->RequestTargets, layers, w, h, GL_RGBA32F);
  this->Cur->Requested.assign(this->Cur->SlotOf.size(), 0);
  this->Cur->RequestedKeys.clear();
  this->Cur->RefineKeys.clear();
  // One key per pixel, or the four of each 2 x 2 block.
  this->KeyPass(
    frame, this->RequestQuad.get(), this->Cur->RequestTargets, w, h, step == 2 ? 4 : 1,
    this->Cur->Keys,
    [&](int layer, vtkShaderProgram* program)
    { this->SetMapUniforms(self, program, frame->GetLayer(layer), setup, true); },
    [](int) {});
  if (!this->MarkRequests(this->Cur->Keys, error))
  {
    return false;
  }
  std::sort(this->Cur->RequestedKeys.begin(), this->Cur->RequestedKeys.end());
  self->NumberOfRequestedPages = static_cast<int>(this->Cur->RequestedKeys.size());
  self->RequestedLevels[0] = self->RequestedLevels[1] = 0;
  if (!this->Cur->RequestedKeys.empty())
  {
    int px, py;
    this->Levels.Decode(this->Cur->RequestedKeys.front(), self->RequestedLevels[0], px, py);
    this->Levels.Decode(this->Cur->RequestedKeys.back(), self->RequestedLevels[1], px, py);
  }
  self->RequestTimeMs = ElapsedMs(start);
  return true;
}

//------------------------------------------------------------------------------
// Shadow-edge refinement (the refine program, RMSM_REFINE in the shader): with the requested
// pages resident, the samples whose 2 x 2 taps straddle a shadow edge request the page
// RefineLevels levels finer; every sample's final level goes to RefineTargets for the
// lookup. The new keys join the requested ones (so allocation never evicts them).
bool vtkPenumbraResolutionMatchedShadows::Internals::Refine(
  vtkPenumbraResolutionMatchedShadows* self, vtkPenumbraFrame* frame, const LightSetup& setup,
  std::string& error)
{
  const auto start = Clock::now();
  const int w = frame->GetWidth(), h = frame->GetHeight();
  EnsureKeyTargets(frame->GetWindow(), this->Cur->RefineTargets,
    static_cast<size_t>(frame->GetNumberOfLayers()), w, h, GL_R32F);
  const size_t before = this->Cur->RequestedKeys.size();
  this->KeyPass(
    frame, this->RefineQuad.get(), this->Cur->RefineTargets, w, h, 1, this->Cur->RefineKeys,
    [&](int layer, vtkShaderProgram* program)
    {
      vtkTextureObject* levels = this->Cur->RequestTargets[2 * static_cast<size_t>(layer) + 1];
      levels->Activate();
      this->SetMapUniforms(self, program, frame->GetLayer(layer), setup, true);
      this->SetLookupUniforms(self, program, levels, self->AnalysisStep, setup);
      program->SetUniformi("refineLevels", self->RefineLevels);
    },
    [&](int layer)
    {
      this->Cur->PageTableAlias->Deactivate();
      this->Atlas->Deactivate();
      this->Cur->RequestTargets[2 * static_cast<size_t>(layer) + 1]->Deactivate();
    });
  if (!this->MarkRequests(this->Cur->RefineKeys, error))
  {
    return false;
  }
  std::sort(this->Cur->RequestedKeys.begin() + static_cast<std::ptrdiff_t>(before),
    this->Cur->RequestedKeys.end());
  self->NumberOfRefinedPages = static_cast<int>(this->Cur->RequestedKeys.size() - before);
  self->RequestTimeMs += ElapsedMs(start);
  return true;
}

//------------------------------------------------------------------------------
// The requested pages made resident: allocated, the page table uploaded, the new pages
// rendered.
bool vtkPenumbraResolutionMatchedShadows::Internals::MakeResident(
  vtkPenumbraResolutionMatchedShadows* self, std::string& error)
{
  const auto start = Clock::now();
  std::vector<NewPage> pages = this->Allocate(self);
  this->UploadTable();
  const bool ok = this->RenderPages(self, pages, error);
  self->PageTimeMs += ElapsedMs(start);
  return ok;
}

//------------------------------------------------------------------------------
// §3.3.3-3.3.5: atlas slots for the whole base level (when flushed) and the requested pages
// that are not resident, coarse levels first. When the free list runs out, the pages no
// sample requested this frame are evicted once; what still does not fit stays out, and its
// samples read the finest resident coarser page. Returns the pages to render.
std::vector<NewPage> vtkPenumbraResolutionMatchedShadows::Internals::Allocate(
  vtkPenumbraResolutionMatchedShadows* self)
{
  std::vector<long long> wanted;
  const int base = this->Levels.Base;
  for (long long key = 0; key < this->Levels.Offset(base + 1); ++key)
  {
    if (this->Cur->SlotOf[static_cast<size_t>(key)] < 0)
    {
      wanted.push_back(key);
    }
  }
  for (long long key : this->Cur->RequestedKeys)
  {
    if (key >= this->Levels.Offset(base + 1) && this->Cur->SlotOf[static_cast<size_t>(key)] < 0)
    {
      wanted.push_back(key);
    }
  }
  bool evicted = false;
  std::vector<NewPage> pages;
  for (long long key : wanted)
  {
    if (this->FreeSlots.empty() && !evicted)
    {
      evicted = true;
      for (long long r = this->Levels.Offset(base + 1); r < this->Levels.Size(); ++r)
      {
        int& slot = this->Cur->SlotOf[static_cast<size_t>(r)];
        if (slot >= 0 && !this->Cur->Requested[static_cast<size_t>(r)])
        {
          this->FreeSlots.push_back(slot);
          slot = -1;
          this->Cur->TableDirty = true;
          this->Cur->Changed.push_back(r);
        }
      }
    }
    if (this->FreeSlots.empty())
    {
      break; // the finer requests stay out: coarser pages serve them
    }
    NewPage page;
    this->Levels.Decode(key, page.K, page.X, page.Y);
    page.Slot = this->FreeSlots.back();
    this->FreeSlots.pop_back();
    this->Cur->SlotOf[static_cast<size_t>(key)] = page.Slot;
    pages.push_back(page);
    this->Cur->TableDirty = true;
    this->Cur->Changed.push_back(key);
  }
  const int capacity = self->GetAtlasCapacity();
  self->NumberOfResidentPages = capacity - static_cast<int>(this->FreeSlots.size());
  size_t requesting = 0, coarser = 0;
  for (const auto* keys : { &this->Cur->Keys, &this->Cur->RefineKeys })
  {
    for (float value : *keys)
    {
      const long long key = static_cast<long long>(value) - 1;
      if (key >= 0)
      {
        ++requesting;
        coarser += this->Cur->SlotOf[static_cast<size_t>(key)] < 0 ? 1 : 0;
      }
    }
  }
  this->Cur->CoarserShare = requesting ? static_cast<double>(coarser) / requesting : 0.0;
  self->CoarserShare = this->Cur->CoarserShare;
  return pages;
}

//------------------------------------------------------------------------------
// The page table's entries, level by level from the base: a resident page's own slot, else
// its parent's entry (the finest resident coarser page), uploaded when anything changed. After
// a flush every entry is computed and uploaded; otherwise only the subtrees of the pages made
// or no longer resident since the last upload, each level's bounding rectangle of them
// uploaded (the refined pages of a frame are a few dozen: the whole table, 1.4 million
// entries at 32768^2, cost a few ms to compute and upload).
void vtkPenumbraResolutionMatchedShadows::Internals::UploadTable()
{
  LightPages& cur = *this->Cur;
  if (!cur.TableDirty)
  {
    return;
  }
  const Pyramid& p = this->Levels;
  const int levels = p.Finest - p.Base + 1;
  // Per level the rectangle to upload, [x0, x1) x [y0, y1).
  std::vector<int> rect(4 * static_cast<size_t>(levels), 0);
  // The entries of level k in [x0, x1) x [y0, y1), their parents' being up to date.
  auto compute = [&](int k, int x0, int x1, int y0, int y1)
  {
    const int side = p.Side(k);
    const int32_t tag = (k - p.Base) << 24;
    for (int y = y0; y < y1; ++y)
    {
      const size_t row = static_cast<size_t>(p.Offset(k)) + static_cast<size_t>(y) * side;
      const int* slots = cur.SlotOf.data() + row;
      int32_t* entries = cur.Table.data() + row;
      // The base level is always resident (it takes at most a quarter of the atlas).
      const int32_t* parents = k == p.Base
        ? nullptr
        : cur.Table.data() + p.Offset(k - 1) + static_cast<size_t>(y >> 1) * (side >> 1);
      for (int x = x0; x < x1; ++x)
      {
        entries[x] = slots[x] >= 0 || !parents ? (tag | std::max(slots[x], 0)) : parents[x >> 1];
      }
    }
    int* r = rect.data() + 4 * (k - p.Base);
    if (r[0] == r[1])
    {
      r[0] = x0, r[1] = x1, r[2] = y0, r[3] = y1;
    }
    else
    {
      r[0] = std::min(r[0], x0), r[1] = std::max(r[1], x1);
      r[2] = std::min(r[2], y0), r[3] = std::max(r[3], y1);
    }
  };
  if (cur.FullTable || cur.Changed.size() > 65536)
  {
    for (int k = p.Base; k <= p.Finest; ++k)
    {
      compute(k, 0, p.Side(k), 0, p.Side(k));
    }
  }
  else
  {
    // Each changed page's subtree, coarse to fine (an overlap is computed twice, alike).
    for (long long key : cur.Changed)
    {
      int k, x, y;
      p.Decode(key, k, x, y);
      for (int kk = k; kk <= p.Finest; ++kk)
      {
        const int d = kk - k;
        compute(kk, x << d, (x + 1) << d, y << d, (y + 1) << d);
      }
    }
  }
  // Direct state access: no texture unit's binding changes under VTK's bookkeeping.
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  for (int k = p.Base; k <= p.Finest; ++k)
  {
    const int* r = rect.data() + 4 * (k - p.Base);
    if (r[0] == r[1])
    {
      continue;
    }
    glPixelStorei(GL_UNPACK_ROW_LENGTH, p.Side(k));
    glTextureSubImage2D(cur.PageTable, p.Finest - k, r[0], r[2], r[1] - r[0], r[3] - r[2],
      GL_RED_INTEGER, GL_INT,
      cur.Table.data() + p.Offset(k) + static_cast<size_t>(r[2]) * p.Side(k) + r[0]);
  }
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  cur.Changed.clear();
  cur.FullTable = false;
  cur.TableDirty = false;
}
