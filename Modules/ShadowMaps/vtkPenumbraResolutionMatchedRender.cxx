// Resolution-matched shadow maps' page rendering (Lefohn et al. 2007, §3.3.3): the new pages
// binned into superpages, rendered into the scratch and copied into their atlas slots.
#include "vtkPenumbraResolutionMatchedShadowsInternals.h"

#include "vtkPenumbraGLPassState.h"
#include "vtkPenumbraShadowMapFS.h"
#include "vtkPenumbraShadowMapVS.h"

namespace
{
// `view` with its s and t rows cropped so that the texels [x0, x0 + w) x [y0, y0 + h) of level
// k (2^k texels per side) fill a w x h viewport, texel centres on pixel centres; the depth row
// is untouched, so depths agree across superpages and levels.
View CroppedView(const View& view, int k, int x0, int y0, int w, int h)
{
  View cropped = view;
  const double side = std::ldexp(1.0, k);
  const int origin[2] = { x0, y0 };
  const int size[2] = { w, h };
  for (int r = 0; r < 2; ++r)
  {
    const double a = side / size[r];
    const double b = (side - 2.0 * origin[r]) / size[r] - 1.0;
    for (int c = 0; c < 4; ++c)
    {
      cropped.Row[r][c] = a * view.Row[r][c] + b * view.Row[3][c];
    }
  }
  return cropped;
}
}
//------------------------------------------------------------------------------
// §3.3.3 (steps 10-12): the new pages binned into superpages (32 x 32 pages of one level);
// per superpage one pass of the casters into the scratch, cropped to the bounding rectangle
// of its new pages, then each page copied into its atlas slot.
bool vtkPenumbraResolutionMatchedShadows::Internals::RenderPages(
  vtkPenumbraResolutionMatchedShadows* self, std::vector<NewPage>& pages, std::string& error)
{
  if (pages.empty())
  {
    return true;
  }
  vtkOpenGLRenderWindow* win = this->Window;
  std::string vs = vtkPenumbraShadowMapVS, fs = vtkPenumbraShadowMapFS;
  if (!this->Cur->Map.Perspective)
  {
    // Orthographic depth is linear already: the rasterizer writes it (early depth test).
    for (std::string* source : { &vs, &fs })
    {
      vtkShaderProgram::Substitute(*source, "//VTK::System::Dec",
        "//VTK::System::Dec\n#define PENUMBRA_HARDWARE_DEPTH\n", false);
    }
  }
  vtkShaderProgram* program = win->GetShaderCache()->ReadyShaderProgram(vs.c_str(), fs.c_str(), "");
  if (!program || !program->GetCompiled())
  {
    error = "the shadow map shaders do not compile or link on this OpenGL implementation";
    return false;
  }
  std::sort(pages.begin(), pages.end());
  vtkOpenGLState* ostate = win->GetState();
  penumbra_gl::MapRenderState renderState(ostate, this->MapFBO, ScratchSide, ScratchSide, false);
  vtkOpenGLState::ScopedglScissor scissor(ostate);
  this->MapFBO->AddDepthAttachment(this->Scratch);
  ostate->vtkglDrawBuffer(GL_NONE);
  ostate->vtkglReadBuffer(GL_NONE);
  ostate->vtkglEnable(GL_SCISSOR_TEST);
  this->Casters.Bind(program);
  program->SetUniformi("perspective", this->Cur->Map.Perspective ? 1 : 0);
  program->SetUniformf("invFar", static_cast<float>(1.0 / this->Cur->Map.Far));
  program->SetUniformi("peel", 0);
  program->SetUniformf("peelGap", 0.0f);
  const size_t perBatch = size_t(1) << (2 * ScratchCellBits);
  std::vector<SuperpageCell> cells;
  std::vector<int> sizes; // per cell of the batch, the bounding rectangle's w and h
  for (size_t first = 0; first < pages.size();)
  {
    // A batch: up to perBatch superpages, each in its cell of the scratch.
    cells.clear();
    sizes.clear();
    while (first < pages.size() && cells.size() < perBatch)
    {
      SuperpageCell cell{ first, first, pages[first].X, pages[first].Y, 0, 0 };
      int x1 = cell.X0, y1 = cell.Y0;
      while (cell.Last < pages.size() && pages[cell.Last].SameSuperpage(pages[first]))
      {
        cell.X0 = std::min(cell.X0, pages[cell.Last].X);
        x1 = std::max(x1, pages[cell.Last].X);
        cell.Y0 = std::min(cell.Y0, pages[cell.Last].Y);
        y1 = std::max(y1, pages[cell.Last].Y);
        ++cell.Last;
      }
      const int index = static_cast<int>(cells.size());
      cell.CellX = (index & ((1 << ScratchCellBits) - 1)) * SuperpageSide;
      cell.CellY = (index >> ScratchCellBits) * SuperpageSide;
      cells.push_back(cell);
      sizes.push_back((x1 - cell.X0 + 1) << PageBits);
      sizes.push_back((y1 - cell.Y0 + 1) << PageBits);
      first = cell.Last;
    }
    // Only the cells' rectangles cleared, before the batch's draws (the previous batch's copies
    // waited for its draws: nothing pending writes the scratch). A clear of the whole 1024^2
    // scratch makes llvmpipe process every tile of it; a scissored clear is a quad drawn.
    const GLfloat one = 1.0f;
    if (glClearTexSubImage)
    {
      for (size_t c = 0; c < cells.size(); ++c)
      {
        glClearTexSubImage(this->Scratch->GetHandle(), 0, cells[c].CellX, cells[c].CellY, 0,
          sizes[2 * c], sizes[2 * c + 1], 1, GL_DEPTH_COMPONENT, GL_FLOAT, &one);
      }
    }
    else
    {
      ostate->vtkglDisable(GL_SCISSOR_TEST);
      glClearBufferfv(GL_DEPTH, 0, &one);
      ostate->vtkglEnable(GL_SCISSOR_TEST);
    }
    for (size_t c = 0; c < cells.size(); ++c)
    {
      const SuperpageCell& cell = cells[c];
      const int w = sizes[2 * c], h = sizes[2 * c + 1];
      const View crop = CroppedView(
        this->Cur->Map, pages[cell.First].K, cell.X0 << PageBits, cell.Y0 << PageBits, w, h);
      float matrix[16];
      crop.ToFloatMatrix(matrix);
      program->SetUniformMatrix4x4("lightMatrix", matrix);
      ostate->vtkglViewport(cell.CellX, cell.CellY, w, h);
      ostate->vtkglScissor(cell.CellX, cell.CellY, w, h);
      this->Casters.Draw();
      ++self->NumberOfSuperpages;
    }
    this->CopyPages(pages, cells);
  }
  self->NumberOfRenderedPages += static_cast<int>(pages.size());
  self->TotalRenderedPages += static_cast<long long>(pages.size());
  return true;
}

//------------------------------------------------------------------------------
// §3.3.3 (step 12): the pages of a batch of rendered superpages copied from their scratch
// cells into their atlas slots (the first copy waits for the batch's draws).
void vtkPenumbraResolutionMatchedShadows::Internals::CopyPages(
  const std::vector<NewPage>& pages, const std::vector<SuperpageCell>& cells)
{
  const GLuint scratch = this->Scratch->GetHandle(), atlas = this->Atlas->GetHandle();
  const int slotsPerRow = static_cast<int>(this->Atlas->GetWidth()) >> PageBits;
  for (const SuperpageCell& cell : cells)
  {
    for (size_t i = cell.First; i < cell.Last;)
    {
      // A run of pages side by side in one row whose slots follow each other in one atlas row
      // (the free list hands out consecutive slots, and allocation goes row by row) is one
      // copy: on llvmpipe each copy costs more than its texels.
      const NewPage& page = pages[i];
      size_t end = i + 1;
      while (end < cell.Last && pages[end].Y == page.Y &&
        pages[end].X == page.X + static_cast<int>(end - i) &&
        pages[end].Slot == page.Slot + static_cast<int>(end - i) &&
        pages[end].Slot / slotsPerRow == page.Slot / slotsPerRow)
      {
        ++end;
      }
      glCopyImageSubData(scratch, GL_TEXTURE_2D, 0, cell.CellX + ((page.X - cell.X0) << PageBits),
        cell.CellY + ((page.Y - cell.Y0) << PageBits), 0, atlas, GL_TEXTURE_2D, 0,
        (page.Slot % slotsPerRow) << PageBits, (page.Slot / slotsPerRow) << PageBits, 0,
        static_cast<int>(end - i) << PageBits, PageSize, 1);
      i = end;
    }
  }
}
