// GEARS' grid of potential blockers (Wang et al. 2014, §3, steps 1-3, A.3): one side's
// samples gathered and binned into the light-space grid, the casters' footprints and ranges,
// and the cells' caster lists.
#include "vtkPenumbraGearsShadowsInternals.h"

//------------------------------------------------------------------------------
// The light frame of this side, z toward the samples (Wang et al. 2014, §4, A.1; the back
// side mirrors), and this side's samples in it (Scratch.Ids, Scratch.Frame). False if the
// side has no samples.
bool vtkPenumbraGearsShadows::Internals::GatherSide(const CallState& call, SideState& S, int flip)
{
  const LightSamples& ls = call.Light;
  S.Flip = flip;
  S.Centre = ls.Centre;
  for (int c = 0; c < 3; ++c)
  {
    S.Ax[0][c] = ls.U[c];
    S.Ax[1][c] = ls.V[c];
    S.Ax[2][c] = flip * ls.N[c];
  }
  const std::vector<signed char>& side = this->Scratch.Side;
  std::vector<vtkIdType>& ids = this->Scratch.Ids;
  ids.clear();
  for (vtkIdType s = 0; s < call.N; ++s)
  {
    if (side[static_cast<size_t>(s)] == flip)
    {
      ids.push_back(s);
    }
  }
  if (ids.empty())
  {
    return false;
  }
  const vtkIdType m = static_cast<vtkIdType>(ids.size());
  S.M = m;
  std::vector<double>& frame = this->Scratch.Frame;
  frame.assign(3 * static_cast<size_t>(m), 0.0);
  double maxScale = call.Diagonal;
  S.ZFar = 0.0;
  const double lo3[3] = { -ls.HalfU, -ls.HalfV, 0.0 }, hi3[3] = { ls.HalfU, ls.HalfV, 0.0 };
  std::copy(lo3, lo3 + 3, S.Lo3);
  std::copy(hi3, hi3 + 3, S.Hi3);
  for (vtkIdType q = 0; q < m; ++q)
  {
    const vtkIdType s = ids[static_cast<size_t>(q)];
    double p[3];
    for (int c = 0; c < 3; ++c)
    {
      p[c] = static_cast<double>(call.Pos[3 * s + c]) + call.Shift[c];
    }
    double* f = &frame[3 * static_cast<size_t>(q)];
    S.ToFrame(p, f);
    f[2] = std::max(f[2], 0.0); // rounding of the side test; z > 0 by construction
    S.ZFar = std::max(S.ZFar, f[2]);
    maxScale = std::max(maxScale, vtkMath::Norm(p));
    for (int c = 0; c < 3; ++c)
    {
      S.Lo3[c] = std::min(S.Lo3[c], f[c]);
      S.Hi3[c] = std::max(S.Hi3[c], f[c]);
    }
  }
  // Triangles within this of the light plane, the far plane or a cell border are treated
  // as touching it: the float32 ray may hit them that much off.
  S.Tolerance = 4.0 * RelativePositionTolerance * maxScale;
  return true;
}

//------------------------------------------------------------------------------
// Camera C behind the light (z < 0) on the line from the AABB centre through the light
// centre, at CameraDistanceFactor x diagonal (Wang et al. 2014, §4, A.1); any z_C < 0 is
// conservative. The samples projected from C onto the far plane (Scratch.Proj) and their
// bounds.
void vtkPenumbraGearsShadows::Internals::PlaceCamera(
  vtkPenumbraGearsShadows* self, const CallState& call, SideState& S)
{
  double dir[3] = { -0.5 * (S.Lo3[0] + S.Hi3[0]), -0.5 * (S.Lo3[1] + S.Hi3[1]),
    -0.5 * (S.Lo3[2] + S.Hi3[2]) };
  if (!(vtkMath::Normalize(dir) > 0.0) || !(dir[2] < -0.25))
  {
    dir[0] = 0.0;
    dir[1] = 0.0;
    dir[2] = -1.0;
  }
  S.Distance =
    std::max(self->CameraDistanceFactor * call.Light.Diagonal, 1e-3 * std::max(S.ZFar, 1e-300));
  for (int c = 0; c < 3; ++c)
  {
    S.Cam[c] = dir[c] * S.Distance;
  }
  const std::vector<double>& frame = this->Scratch.Frame;
  std::vector<double>& proj = this->Scratch.Proj;
  proj.assign(2 * static_cast<size_t>(S.M), 0.0);
  double* pb = S.Pb;
  pb[0] = std::numeric_limits<double>::infinity();
  pb[1] = -std::numeric_limits<double>::infinity();
  pb[2] = std::numeric_limits<double>::infinity();
  pb[3] = -std::numeric_limits<double>::infinity();
  for (vtkIdType q = 0; q < S.M; ++q)
  {
    double* pr = &proj[2 * static_cast<size_t>(q)];
    S.Project(&frame[3 * static_cast<size_t>(q)], pr);
    pb[0] = std::min(pb[0], pr[0]);
    pb[1] = std::max(pb[1], pr[0]);
    pb[2] = std::min(pb[2], pr[1]);
    pb[3] = std::max(pb[3], pr[1]);
  }
  S.Extent = std::max({ pb[1] - pb[0], pb[3] - pb[2], 1e-9 * (S.ZFar + S.Distance) });
}

//------------------------------------------------------------------------------
// Per caster on this side: culled, global (touches the light plane) or the box on the far
// plane that its shadow can reach (Wang et al. 2014, A.3, in closed form in the light's
// frame: extrusion rectangles and projections from C).
void vtkPenumbraGearsShadows::Internals::CasterFootprints(const CallState& call, SideState& S)
{
  const LightSamples& ls = call.Light;
  const vtkIdType nCasters = static_cast<vtkIdType>(this->Casters.size());
  S.ZNear.assign(static_cast<size_t>(nCasters), 0.0);
  S.Foot.resize(static_cast<size_t>(nCasters));
  std::vector<double>& triBoxes = this->Scratch.TriangleBoxes;
  triBoxes.resize(6 * static_cast<size_t>(nCasters));
  const double tolerance = S.Tolerance, zFar = S.ZFar;
  vtkSMPTools::For(0, nCasters,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType t = begin; t < end; ++t)
      {
        const Caster& tri = this->Casters[static_cast<size_t>(t)];
        Footprint& fp = S.Foot[static_cast<size_t>(t)];
        double f[3][3];
        double zmin = std::numeric_limits<double>::infinity(), zmax = -zmin;
        for (int i = 0; i < 3; ++i)
        {
          S.ToFrame(tri.V[i], f[i]);
          zmin = std::min(zmin, f[i][2]);
          zmax = std::max(zmax, f[i][2]);
        }
        S.ZNear[static_cast<size_t>(t)] = zmin;
        double* tb = &triBoxes[6 * static_cast<size_t>(t)];
        for (int a = 0; a < 3; ++a)
        {
          tb[2 * a] = std::min({ f[0][a], f[1][a], f[2][a] }) - tolerance;
          tb[2 * a + 1] = std::max({ f[0][a], f[1][a], f[2][a] }) + tolerance;
        }
        if (zmax < -tolerance || zmin > zFar + tolerance)
        {
          fp.State = 0; // wholly behind the light plane or beyond every sample
          continue;
        }
        if (zmin <= tolerance)
        {
          fp.State = 1; // touches the light plane: unbounded extrusion
          continue;
        }
        double box[4] = { std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity() };
        double rmax = 1.0;
        for (int i = 0; i < 3; ++i)
        {
          const double r = zFar / f[i][2];
          rmax = std::max(rmax, r);
          const double hx = std::fabs(r - 1.0) * ls.HalfU;
          const double hy = std::fabs(r - 1.0) * ls.HalfV;
          box[0] = std::min(box[0], r * f[i][0] - hx);
          box[1] = std::max(box[1], r * f[i][0] + hx);
          box[2] = std::min(box[2], r * f[i][1] - hy);
          box[3] = std::max(box[3], r * f[i][1] + hy);
          double pc[2];
          S.Project(f[i], pc);
          box[0] = std::min(box[0], pc[0]);
          box[1] = std::max(box[1], pc[0]);
          box[2] = std::min(box[2], pc[1]);
          box[3] = std::max(box[3], pc[1]);
        }
        const double pad =
          2.0 * tolerance * (rmax + (zFar - S.Cam[2]) / (-S.Cam[2])) + 1e-9 * S.Extent;
        fp.Box[0] = box[0] - pad;
        fp.Box[1] = box[1] + pad;
        fp.Box[2] = box[2] - pad;
        fp.Box[3] = box[3] + pad;
        fp.State = std::isfinite(pad) && std::isfinite(box[0] + box[1] + box[2] + box[3]) ? 2 : 1;
      }
    });
}

//------------------------------------------------------------------------------
// The grid and its lists at GridResolution, coarsened while the lists would exceed
// MaxListEntries (Wang et al. 2014, A.2-A.3).
void vtkPenumbraGearsShadows::Internals::BuildGrid(
  vtkPenumbraGearsShadows* self, const CallState& call, SideState& S)
{
  ScratchArrays& sc = this->Scratch;
  sc.SampleCell.assign(static_cast<size_t>(S.M), 0);
  for (auto* v : { &sc.CellStart, &sc.CellList, &sc.GlobalList, &sc.SampleOrder, &sc.SampleStart })
  {
    v->clear();
  }
  sc.Occupied.clear();
  S.G = self->GridResolution;
  for (;;)
  {
    this->BinSamples(S);
    this->CasterRanges(S);
    this->MarkTracedCells(call, S);
    const int g = S.G;
    if (S.Total > static_cast<std::int64_t>(self->MaxListEntries) && g > 1)
    {
      vtkWarningWithObjectMacro(self,
        "GEARS lists would hold " << S.Total << " entries (limit " << self->MaxListEntries
                                  << ") at a " << g << "^2 grid; coarsening to " << g / 2 << "^2");
      S.G /= 2;
      continue;
    }
    if (g == 1)
    {
      // Every remaining caster covers the single cell: list them once, globally.
      for (size_t t = 0; t < this->Casters.size(); ++t)
      {
        if (S.Touched[t] > 0)
        {
          sc.GlobalList.push_back(static_cast<std::uint32_t>(t));
        }
      }
      sc.CellStart.assign(2, 0);
      sc.CellList.clear();
      S.Total = 0;
      break;
    }
    this->FillCellLists(S);
    break;
  }
}

//------------------------------------------------------------------------------
// Wang et al. 2014, A.2: the grid over the projected samples, and the samples binned by cell
// (counting sort), with the occupied cells and a summed-area table of them.
void vtkPenumbraGearsShadows::Internals::BinSamples(SideState& S)
{
  ScratchArrays& sc = this->Scratch;
  const int g = S.G;
  const vtkIdType m = S.M;
  const double* pb = S.Pb;
  const double extent = S.Extent;
  const double x0 = S.X0 = pb[0] - 1e-9 * extent;
  const double y0 = S.Y0 = pb[2] - 1e-9 * extent;
  const double cw = S.Cw = std::max(pb[1] - pb[0], 1e-6 * extent) * (1.0 + 1e-7) / g;
  const double ch = S.Ch = std::max(pb[3] - pb[2], 1e-6 * extent) * (1.0 + 1e-7) / g;
  const size_t cells = static_cast<size_t>(g) * g;
  auto cellOf = [&](double px, double py, int& ix, int& iy)
  {
    ix = static_cast<int>(std::min<double>(g - 1, std::max(0.0, std::floor((px - x0) / cw))));
    iy = static_cast<int>(std::min<double>(g - 1, std::max(0.0, std::floor((py - y0) / ch))));
  };
  std::vector<std::uint32_t>& count = S.Count;
  count.assign(cells + 1, 0);
  const std::vector<double>& proj = sc.Proj;
  for (vtkIdType q = 0; q < m; ++q)
  {
    int ix, iy;
    cellOf(proj[2 * q], proj[2 * q + 1], ix, iy);
    sc.SampleCell[static_cast<size_t>(q)] = iy * g + ix;
    ++count[static_cast<size_t>(iy * g + ix)];
  }
  // Summed-area table of occupancy: cells a footprint touches, counted in O(1).
  std::vector<std::int64_t>& sat = S.Sat;
  sat.assign(static_cast<size_t>(g + 1) * (g + 1), 0);
  sc.Occupied.clear();
  for (int iy = 0; iy < g; ++iy)
  {
    for (int ix = 0; ix < g; ++ix)
    {
      const bool busy = count[static_cast<size_t>(iy * g + ix)] > 0;
      if (busy)
      {
        sc.Occupied.push_back(iy * g + ix);
      }
      sat[static_cast<size_t>(iy + 1) * (g + 1) + ix + 1] = (busy ? 1 : 0) +
        sat[static_cast<size_t>(iy) * (g + 1) + ix + 1] +
        sat[static_cast<size_t>(iy + 1) * (g + 1) + ix] -
        sat[static_cast<size_t>(iy) * (g + 1) + ix];
    }
  }
  std::vector<std::uint32_t>& sampleStart = sc.SampleStart;
  sampleStart.assign(cells + 1, 0);
  for (size_t c = 0; c < cells; ++c)
  {
    sampleStart[c + 1] = sampleStart[c] + count[c];
  }
  sc.SampleOrder.resize(static_cast<size_t>(m));
  std::vector<std::uint32_t> cursor(sampleStart.begin(), sampleStart.end() - 1);
  for (vtkIdType q = 0; q < m; ++q)
  {
    sc.SampleOrder[cursor[static_cast<size_t>(sc.SampleCell[static_cast<size_t>(q)])]++] =
      static_cast<std::uint32_t>(q);
  }
}

//------------------------------------------------------------------------------
// Wang et al. 2014, A.3: each caster's footprint as a range of cells; those that would enter
// more than half the busy cells join the global list instead (Scratch.GlobalList).
void vtkPenumbraGearsShadows::Internals::CasterRanges(SideState& S)
{
  const vtkIdType nCasters = static_cast<vtkIdType>(this->Casters.size());
  const int g = S.G;
  const double x0 = S.X0, y0 = S.Y0, cw = S.Cw, ch = S.Ch;
  const std::vector<std::int64_t>& sat = S.Sat;
  std::vector<int>& range = S.Range;
  std::vector<std::int64_t>& touched = S.Touched;
  range.assign(4 * static_cast<size_t>(nCasters), 0);
  touched.assign(static_cast<size_t>(nCasters), 0);
  const std::int64_t busyCells = static_cast<std::int64_t>(this->Scratch.Occupied.size());
  vtkSMPTools::For(0, nCasters,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType t = begin; t < end; ++t)
      {
        const Footprint& fp = S.Foot[static_cast<size_t>(t)];
        int* rg = &range[4 * static_cast<size_t>(t)];
        if (fp.State != 2)
        {
          touched[static_cast<size_t>(t)] = fp.State == 1 ? -1 : 0;
          continue;
        }
        const double bx0 = std::floor((fp.Box[0] - x0) / cw),
                     bx1 = std::floor((fp.Box[1] - x0) / cw);
        const double by0 = std::floor((fp.Box[2] - y0) / ch),
                     by1 = std::floor((fp.Box[3] - y0) / ch);
        if (bx1 < 0 || by1 < 0 || bx0 > g - 1 || by0 > g - 1)
        {
          touched[static_cast<size_t>(t)] = 0;
          continue;
        }
        rg[0] = static_cast<int>(std::max(0.0, bx0));
        rg[1] = static_cast<int>(std::min<double>(g - 1, bx1));
        rg[2] = static_cast<int>(std::max(0.0, by0));
        rg[3] = static_cast<int>(std::min<double>(g - 1, by1));
        const std::int64_t c = sat[static_cast<size_t>(rg[3] + 1) * (g + 1) + rg[1] + 1] -
          sat[static_cast<size_t>(rg[2]) * (g + 1) + rg[1] + 1] -
          sat[static_cast<size_t>(rg[3] + 1) * (g + 1) + rg[0]] +
          sat[static_cast<size_t>(rg[2]) * (g + 1) + rg[0]];
        // A list entry in more than half the busy cells costs more than one global entry.
        touched[static_cast<size_t>(t)] = (busyCells > 8 && 2 * c > busyCells) ? -1 : c;
      }
    });
  std::vector<std::uint32_t>& globalList = this->Scratch.GlobalList;
  std::int64_t total = 0;
  globalList.clear();
  for (vtkIdType t = 0; t < nCasters; ++t)
  {
    const std::int64_t c = touched[static_cast<size_t>(t)];
    if (c < 0)
    {
      globalList.push_back(static_cast<std::uint32_t>(t));
    }
    else
    {
      total += c;
    }
  }
  S.Total = total;
}

//------------------------------------------------------------------------------
// The cell lists (Wang et al. 2014, A.3): a counting sort of (caster, cell) pairs by cell,
// busy untraced cells only, each list sorted largest triangle first.
void vtkPenumbraGearsShadows::Internals::FillCellLists(SideState& S)
{
  ScratchArrays& sc = this->Scratch;
  const vtkIdType nCasters = static_cast<vtkIdType>(this->Casters.size());
  const int g = S.G;
  const size_t cells = static_cast<size_t>(g) * g;
  std::vector<std::atomic<std::uint32_t>> perCell(cells);
  for (auto& a : perCell)
  {
    a.store(0, std::memory_order_relaxed);
  }
  // Per row, the columns of the cells that get a list (busy, not dense), so a caster's
  // range costs its list entries, not its area: under a large light the footprints span
  // thousands of cells, most of them empty or dense. A summed-area table of those cells
  // skips the casters (most of a dense mesh) whose range holds none.
  std::vector<std::uint32_t> rowStart(static_cast<size_t>(g) + 1, 0);
  std::vector<int> columns;
  std::vector<std::uint32_t> listed(static_cast<size_t>(g + 1) * (g + 1), 0);
  for (const std::int32_t c : sc.Occupied) // row-major order
  {
    if (!sc.Traced[static_cast<size_t>(c)])
    {
      columns.push_back(c % g);
      ++rowStart[static_cast<size_t>(c / g) + 1];
      listed[static_cast<size_t>(c / g + 1) * (g + 1) + c % g + 1] = 1;
    }
  }
  for (int iy = 0; iy < g; ++iy)
  {
    rowStart[static_cast<size_t>(iy) + 1] += rowStart[static_cast<size_t>(iy)];
  }
  for (int iy = 1; iy <= g; ++iy)
  {
    for (int ix = 1; ix <= g; ++ix)
    {
      const size_t at = static_cast<size_t>(iy) * (g + 1) + ix;
      listed[at] += listed[at - 1] + listed[at - (g + 1)] - listed[at - (g + 1) - 1];
    }
  }
  auto forCells = [&](vtkIdType t, auto&& fn)
  {
    const int* rg = &S.Range[4 * static_cast<size_t>(t)];
    const size_t w = static_cast<size_t>(g) + 1;
    if (listed[(rg[3] + 1) * w + rg[1] + 1] - listed[rg[2] * w + rg[1] + 1] -
        listed[(rg[3] + 1) * w + rg[0]] + listed[rg[2] * w + rg[0]] ==
      0)
    {
      return;
    }
    for (int iy = rg[2]; iy <= rg[3]; ++iy)
    {
      const auto rowEnd = columns.begin() + rowStart[static_cast<size_t>(iy) + 1];
      for (auto it =
             std::lower_bound(columns.begin() + rowStart[static_cast<size_t>(iy)], rowEnd, rg[0]);
           it != rowEnd && *it <= rg[1]; ++it)
      {
        fn(static_cast<size_t>(iy) * g + *it);
      }
    }
  };
  vtkSMPTools::For(0, nCasters,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType t = begin; t < end; ++t)
      {
        if (S.Touched[static_cast<size_t>(t)] > 0)
        {
          forCells(t, [&](size_t cell) { perCell[cell].fetch_add(1, std::memory_order_relaxed); });
        }
      }
    });
  std::vector<std::uint32_t>& cellStart = sc.CellStart;
  std::vector<std::uint32_t>& cellList = sc.CellList;
  cellStart.assign(cells + 1, 0);
  for (size_t c = 0; c < cells; ++c)
  {
    cellStart[c + 1] = cellStart[c] + perCell[c].load(std::memory_order_relaxed);
    perCell[c].store(cellStart[c], std::memory_order_relaxed);
  }
  cellList.resize(static_cast<size_t>(cellStart[cells]));
  vtkSMPTools::For(0, nCasters,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType t = begin; t < end; ++t)
      {
        if (S.Touched[static_cast<size_t>(t)] > 0)
        {
          forCells(t,
            [&](size_t cell)
            {
              cellList[perCell[cell].fetch_add(1, std::memory_order_relaxed)] =
                static_cast<std::uint32_t>(t);
            });
        }
      }
    });
  // Largest triangles first: a sample in umbra fills its mask and stops sooner. The
  // order also makes the lists (and the statistics) independent of thread timing.
  const auto& bounds = this->Bounds;
  vtkSMPTools::For(0, static_cast<vtkIdType>(sc.Occupied.size()),
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType b = begin; b < end; ++b)
      {
        const size_t cell = static_cast<size_t>(sc.Occupied[static_cast<size_t>(b)]);
        std::sort(cellList.begin() + cellStart[cell], cellList.begin() + cellStart[cell + 1],
          [&](std::uint32_t x, std::uint32_t y) {
            return bounds[x].Radius > bounds[y].Radius ||
              (bounds[x].Radius == bounds[y].Radius && x < y);
          });
      }
    });
}
