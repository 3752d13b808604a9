// vtkPenumbraShadowVolumeShadows: the edge resolve, the volumes' outline from the camera and the
// samples near it (or not countable) traced exactly.

#include "vtkFloatArray.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraShadowVolumeInternals.h"
#include "vtkSMPTools.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <numeric>

namespace penumbra_shadow_volume
{
// From volume triangles (as drawn: light caps first does not matter) and segments that
// are always on the outline, with their points' identities (VolumeStream) over a mesh of
// `meshPoints` points. Points are numbered in order of first use.
void VolumeOutline::Build(
  const VolumeStream& triangles, const VolumeStream& forced, size_t meshPoints)
{
  this->Clear();
  std::vector<int> number(2 * meshPoints, -1);
  auto point = [&](const VolumeStream& from, size_t vertex)
  {
    int& n = number[static_cast<size_t>(from.Id[vertex])];
    if (n < 0)
    {
      n = static_cast<int>(this->Points.size());
      const float* v = from.V.data() + 4 * vertex;
      this->Points.push_back({ v[0], v[1], v[2], v[3] });
      this->PointId.push_back(from.Id[vertex]);
    }
    return n;
  };
  const size_t nt = triangles.Id.size() / 3;
  this->Faces.resize(nt);
  for (size_t t = 0; t < nt; ++t)
  {
    for (int k = 0; k < 3; ++k)
    {
      this->Faces[t][static_cast<size_t>(k)] = point(triangles, 3 * t + static_cast<size_t>(k));
    }
  }
  // The face edges (first, second, incidence) in lexicographic order: bucketed by their
  // first point (a counting sort), then each small bucket sorted.
  std::vector<int> bucket(this->Points.size() + 1, 0);
  for (const auto& f : this->Faces)
  {
    for (int k = 0; k < 3; ++k)
    {
      ++bucket[static_cast<size_t>(std::min(f[static_cast<size_t>(k)], f[(k + 1) % 3])) + 1];
    }
  }
  std::partial_sum(bucket.begin(), bucket.end(), bucket.begin());
  std::vector<std::array<int, 3>> entries(3 * nt);
  std::vector<int> next(bucket.begin(), bucket.end() - 1);
  for (size_t t = 0; t < nt; ++t)
  {
    const auto& f = this->Faces[t];
    for (int k = 0; k < 3; ++k)
    {
      const int a = f[static_cast<size_t>(k)], b = f[static_cast<size_t>((k + 1) % 3)];
      entries[static_cast<size_t>(next[static_cast<size_t>(std::min(a, b))]++)] = { std::min(a, b),
        std::max(a, b), 2 * static_cast<int>(t) + (a < b) };
    }
  }
  for (size_t p = 0; p + 1 < bucket.size(); ++p)
  {
    std::sort(entries.begin() + bucket[p], entries.begin() + bucket[p + 1]);
  }
  for (size_t i = 0; i < entries.size(); ++i)
  {
    if (i == 0 || entries[i][0] != entries[i - 1][0] || entries[i][1] != entries[i - 1][1])
    {
      this->Edges.push_back({ entries[i][0], entries[i][1] });
      this->EdgeStart.push_back(static_cast<int>(i));
    }
    this->Incidences.push_back(entries[i][2]);
  }
  this->EdgeStart.push_back(static_cast<int>(entries.size()));
  for (size_t i = 0; i + 1 < forced.Id.size(); i += 2)
  {
    this->Forced.push_back({ point(forced, i), point(forced, i + 1) });
  }
}

// Marks in `pixels` (width x height, one view) every pixel whose centre lies within Reach
// of an outline edge projected with `projection` (rebased world -> clip, VTK's camera).
void VolumeOutline::Mark(
  const double projection[4][4], int width, int height, std::vector<unsigned char>& pixels)
{
  this->Projected.resize(this->Points.size());
  for (size_t i = 0; i < this->Points.size(); ++i)
  {
    const auto& p = this->Points[i];
    for (int r : { 0, 1, 3 })
    {
      this->Projected[i][r == 3 ? 2 : r] = projection[r][0] * p[0] + projection[r][1] * p[1] +
        projection[r][2] * p[2] + projection[r][3] * p[3];
    }
  }
  // The sign of det(x y w) of a face: its screen winding for any signs of w.
  this->FaceSide.resize(this->Faces.size());
  for (size_t t = 0; t < this->Faces.size(); ++t)
  {
    const auto& a = this->Projected[static_cast<size_t>(this->Faces[t][0])];
    const auto& b = this->Projected[static_cast<size_t>(this->Faces[t][1])];
    const auto& c = this->Projected[static_cast<size_t>(this->Faces[t][2])];
    const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
      a[2] * (b[0] * c[1] - b[1] * c[0]);
    this->FaceSide[t] = det > 0.0 ? 1 : (det < 0.0 ? -1 : 0);
  }
  for (size_t e = 0; e < this->Edges.size(); ++e)
  {
    if (!this->Skip.empty() &&
      std::binary_search(this->Skip.begin(), this->Skip.end(),
        Pair(this->PointId[static_cast<size_t>(this->Edges[e][0])],
          this->PointId[static_cast<size_t>(this->Edges[e][1])])))
    {
      continue; // a cap interior's edge: judged with both its caps by MarkOutline
    }
    // Faces on the left of first -> second minus those on the right, per winding: the
    // count is continuous across the edge only if both balance (and no face is edge-on).
    int front = 0, back = 0;
    bool onEdge = false;
    for (int i = this->EdgeStart[e]; i < this->EdgeStart[e + 1]; ++i)
    {
      const int side =
        this->FaceSide[static_cast<size_t>(this->Incidences[static_cast<size_t>(i)] / 2)];
      const int forward = this->Incidences[static_cast<size_t>(i)] % 2 ? 1 : -1;
      onEdge = onEdge || side == 0;
      (side > 0 ? front : back) += forward;
    }
    if (onEdge || front != 0 || back != 0)
    {
      MarkSegment(this->Projected[static_cast<size_t>(this->Edges[e][0])],
        this->Projected[static_cast<size_t>(this->Edges[e][1])], width, height, pixels);
    }
  }
  for (const auto& f : this->Forced)
  {
    MarkSegment(this->Projected[static_cast<size_t>(f[0])],
      this->Projected[static_cast<size_t>(f[1])], width, height, pixels);
  }
}

// The segment between two points, clipped in homogeneous coordinates to the view widened
// by two pixels (which also keeps w > 0), then every pixel centre within Reach of it.
void VolumeOutline::MarkSegment(const std::array<double, 3>& p, const std::array<double, 3>& q,
  int width, int height, std::vector<unsigned char>& pixels)
{
  if (q < p)
  {
    // One order for both: a segment's pixels do not depend on which end it is given from
    // (the clipping and the row walk below round differently for the two orders).
    MarkSegment(q, p, width, height, pixels);
    return;
  }
  double t0 = 0.0, t1 = 1.0;
  const double kx = 1.0 + 4.0 / width, ky = 1.0 + 4.0 / height;
  // Planes k w + x >= 0, k w - x >= 0, the same for y.
  const double planes[4][2] = { { kx, 1.0 }, { kx, -1.0 }, { ky, 1.0 }, { ky, -1.0 } };
  for (int k = 0; k < 4; ++k)
  {
    const int axis = k / 2;
    const double d0 = planes[k][0] * p[2] + planes[k][1] * p[static_cast<size_t>(axis)];
    const double d1 = planes[k][0] * q[2] + planes[k][1] * q[static_cast<size_t>(axis)];
    if (d0 < 0.0 && d1 < 0.0)
    {
      return;
    }
    if (d0 < 0.0)
    {
      t0 = std::max(t0, d0 / (d0 - d1));
    }
    else if (d1 < 0.0)
    {
      t1 = std::min(t1, d0 / (d0 - d1));
    }
  }
  if (!(t0 <= t1))
  {
    return;
  }
  double end[2][2];
  for (int e = 0; e < 2; ++e)
  {
    const double t = e == 0 ? t0 : t1;
    const double w = p[2] + t * (q[2] - p[2]);
    if (!(w > 0.0))
    {
      return; // through the eye: nothing of it is on the view
    }
    end[e][0] = 0.5 * ((p[0] + t * (q[0] - p[0])) / w + 1.0) * width;
    end[e][1] = 0.5 * ((p[1] + t * (q[1] - p[1])) / w + 1.0) * height;
  }
  const double r = Reach;
  const double ylo = std::min(end[0][1], end[1][1]), yhi = std::max(end[0][1], end[1][1]);
  const int rowFirst = std::max(0, static_cast<int>(std::ceil(ylo - r - 0.5)));
  const int rowLast = std::min(height - 1, static_cast<int>(std::floor(yhi + r - 0.5)));
  const double dy = end[1][1] - end[0][1];
  for (int y = rowFirst; y <= rowLast; ++y)
  {
    // The part of the segment within Reach of the row's centre line, in x.
    double ta = 0.0, tb = 1.0;
    if (std::fabs(dy) > 1e-12)
    {
      ta = (y + 0.5 - r - end[0][1]) / dy;
      tb = (y + 0.5 + r - end[0][1]) / dy;
      if (ta > tb)
      {
        std::swap(ta, tb);
      }
      ta = std::max(ta, 0.0);
      tb = std::min(tb, 1.0);
      if (ta > tb)
      {
        continue;
      }
    }
    const double xa = end[0][0] + ta * (end[1][0] - end[0][0]);
    const double xb = end[0][0] + tb * (end[1][0] - end[0][0]);
    const int first = std::max(0, static_cast<int>(std::ceil(std::min(xa, xb) - r - 0.5)));
    const int last = std::min(width - 1, static_cast<int>(std::floor(std::max(xa, xb) + r - 0.5)));
    for (int x = first; x <= last; ++x)
    {
      pixels[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)] = 1;
    }
  }
}
}

using namespace penumbra_shadow_volume;

namespace
{
// Below this cosine between the sample normal and the light direction a sample is traced
// (see the edge resolve): about 0.06 degrees from grazing.
constexpr double GrazingCosine = 1e-3;

// Which pending samples (`state`) to trace: those the stencil could not count (see
// SampleLayout) and, with the edge resolve (`outline` given: one view's pixels within reach of
// the volumes' outline, see VolumeOutline), those whose answer may hang on the rasterizer's
// rounding: on the outline, next to a neighbour with another result or next to a pixel that
// is not counted (background, facing away: outlines and terminators), or grazed by the
// light. The outline alone covers every snapping error; the neighbour test stays for the
// depth side of the count (a receiver meeting a volume face within float depth rounding).
// Returns the number of samples marked in `mask`.
vtkIdType MarkTraced(const SampleLayout& layout, const penumbra_light_views::FrameInputs& in,
  const VolumeLight& light, const std::vector<unsigned char>& state, const float* vis,
  const unsigned char* outline, unsigned char* mask)
{
  const vtkIdType perLayer = static_cast<vtkIdType>(layout.Width) * layout.Height;
  vtkIdType traced = 0;
  for (vtkIdType s = 0; s < in.NumberOfSamples; ++s)
  {
    mask[s] = 0;
    if (state[static_cast<size_t>(s)] != Pending)
    {
      continue;
    }
    const vtkIdType pixel = layout.Pixel[static_cast<size_t>(s)];
    const bool resolve = outline != nullptr;
    bool edge = pixel < 0 || (resolve && outline[pixel % perLayer]);
    const vtkIdType layerStart = pixel - pixel % perLayer;
    const int x = static_cast<int>(pixel % perLayer % layout.Width);
    const int y = static_cast<int>(pixel % perLayer / layout.Width);
    for (int dy = -1; dy <= 1 && resolve && !edge; ++dy)
    {
      for (int dx = -1; dx <= 1 && !edge; ++dx)
      {
        const int nx = x + dx, ny = y + dy;
        if (nx < 0 || ny < 0 || nx >= layout.Width || ny >= layout.Height)
        {
          continue;
        }
        const vtkIdType t = layout.SampleAt[static_cast<size_t>(
          layerStart + static_cast<vtkIdType>(ny) * layout.Width + nx)];
        // A background neighbour: an outline. A facing-away one: the light's terminator,
        // where the sample's own caster has a silhouette edge and its side quads start.
        edge = t < 0 || state[static_cast<size_t>(t)] != Pending || vis[t] != vis[s];
      }
    }
    if (resolve && !edge)
    {
      // A light grazing the surface (the N.L ~ 0 case): the shadow boundary then slides
      // along the surface with every rounding of the sample (the G-buffer's float position
      // vs. the exact plane the stencil tests), so only a ray decides it as the reference
      // does.
      const float* nn = in.Normals + 3 * s;
      double l[3];
      for (int c = 0; c < 3; ++c)
      {
        l[c] = light.Directional
          ? light.Direction[c]
          : light.Position[c] - (static_cast<double>(in.Positions[3 * s + c]) + in.Shift[c]);
      }
      const double len = std::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
      const double cosine = (nn[0] * l[0] + nn[1] * l[1] + nn[2] * l[2]) / len;
      edge = !(cosine > GrazingCosine);
    }
    mask[s] = edge ? 1 : 0;
    traced += edge;
  }
  return traced;
}
}

// ---- Samples the stencil could not count, and the edge resolve (see MarkTraced), traced
// exactly. False when tracing failed (the visibility is then emptied).
bool vtkPenumbraShadowVolumeShadows::Internals::TraceUncertain(
  vtkPenumbraShadowVolumeShadows& self, const Group& g, const Job& job)
{
  const SampleLayout& layout = this->Layout;
  if (!self.Resolve && layout.Unplaced <= 0)
  {
    return true;
  }
  const vtkIdType n = g.N;
  const auto resolveStart = Clock::now();
  this->Mask->SetNumberOfComponents(1);
  this->Mask->SetNumberOfTuples(n);
  if (self.Resolve)
  {
    this->MarkOutline(*job.Volumes, layout.Width, layout.Height);
  }
  const vtkIdType traced = MarkTraced(layout, *g.In, job.VL, job.State, job.Vis,
    self.Resolve ? this->OutlinePixels.data() : nullptr, n ? this->Mask->GetPointer(0) : nullptr);
  if (traced > 0)
  {
    self.Reference->SetGeometry(g.Geometry);
    LimitBlockers(self, g, job, this->Mask->GetPointer(0));
    if (!self.Reference->ComputeVisibility(g.Samples, job.Light, job.Visibility, this->Mask))
    {
      vtkErrorWithObjectMacro(&self, << "shadow volumes: tracing the edge samples failed: "
                                     << self.Reference->GetErrorMessage());
      job.Visibility->SetNumberOfTuples(0);
      return false;
    }
  }
  self.NumberOfResolvedSamples += traced;
  self.ResolveTimeMs += ElapsedMs(resolveStart);
  return true;
}

namespace
{
// Clip x, y, w of a homogeneous point under `projection` (VolumeOutline::Mark's).
std::array<double, 3> Project(const double projection[4][4], const float xyzw[4])
{
  std::array<double, 3> out;
  int i = 0;
  for (int r : { 0, 1, 3 })
  {
    out[static_cast<size_t>(i++)] = projection[r][0] * xyzw[0] + projection[r][1] * xyzw[1] +
      projection[r][2] * xyzw[2] + projection[r][3] * xyzw[3];
  }
  return out;
}

// The sign of det(x y w) of a projected triangle: its screen winding (VolumeOutline::Mark's).
signed char Side(
  const std::array<double, 3>& a, const std::array<double, 3>& b, const std::array<double, 3>& c)
{
  const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
    a[2] * (b[0] * c[1] - b[1] * c[0]);
  return det > 0.0 ? 1 : (det < 0.0 ? -1 : 0);
}

// The identity pairs of the same-kind edges (both near or both far copies) of explicit
// triangles, sorted: a component edge with one of them is not a cap interior's alone.
std::vector<std::uint64_t> ExplicitPairs(std::initializer_list<const VolumeStream*> streams)
{
  std::vector<std::uint64_t> pairs;
  for (const VolumeStream* s : streams)
  {
    for (size_t t = 0; t + 2 < s->Id.size(); t += 3)
    {
      for (size_t k = 0; k < 3; ++k)
      {
        const int a = s->Id[t + k], b = s->Id[t + (k + 1) % 3];
        if (a % 2 == b % 2)
        {
          pairs.push_back(VolumeOutline::Pair(a, b));
        }
      }
    }
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}
}

// The outline's kept part (VolumeOutline::Build): the explicit volumes, and the caps of the
// faces next to an edge that is not a cap interior's (a silhouette or boundary edge of the
// set, or one that explicit triangles share); the cap interiors' edges among their edges are
// skipped there, MarkOutline judges them.
void vtkPenumbraShadowVolumeShadows::Internals::BuildOutline(VolumeSet& build,
  const Connectivity& mesh, const VolumeStream& gpuVolumes, const VolumeStream& gpuUncertain)
{
  const std::vector<std::uint64_t> shared = ExplicitPairs({ &build.LightCaps, &build.Rest });
  auto isShared = [&](std::uint64_t pair)
  { return std::binary_search(shared.begin(), shared.end(), pair); };
  VolumeStream triangles;
  triangles.Append(build.LightCaps);
  triangles.Append(build.Rest);
  triangles.Append(gpuVolumes);
  std::vector<std::uint64_t> skip;
  for (size_t ci = 0; ci < mesh.Components.size(); ++ci)
  {
    const Connectivity::Component& c = mesh.Components[ci];
    const std::vector<signed char>& set = build.Sets[ci];
    if (set.empty())
    {
      continue;
    }
    // Per face: bit `kind` (0 light cap, 1 dark cap) when that cap is kept explicit.
    std::vector<unsigned char> kept(c.Faces.size(), 0);
    auto interior = [&](const std::array<int, 4>& e, int kind)
    {
      const signed char s0 = set[static_cast<size_t>(e[2])];
      const signed char s1 = e[3] >= 0 ? set[static_cast<size_t>(e[3])] : 0;
      return s0 == s1 && s0 != 0 &&
        !isShared(VolumeOutline::Pair(2 * e[0] + kind, 2 * e[1] + kind));
    };
    c.ForEachEdge(
      [&](const std::array<int, 4>& e)
      {
        for (int kind = 0; kind < 2; ++kind)
        {
          if (!interior(e, kind))
          {
            for (int f : { e[2], e[3] })
            {
              if (f >= 0 && set[static_cast<size_t>(f)] != 0)
              {
                kept[static_cast<size_t>(f)] |= static_cast<unsigned char>(1 << kind);
              }
            }
          }
        }
      });
    c.ForEachEdge(
      [&](const std::array<int, 4>& e)
      {
        for (int kind = 0; kind < 2; ++kind)
        {
          const bool keptSide = (kept[static_cast<size_t>(e[2])] >> kind & 1) ||
            (e[3] >= 0 && (kept[static_cast<size_t>(e[3])] >> kind & 1));
          if (keptSide && interior(e, kind))
          {
            skip.push_back(VolumeOutline::Pair(2 * e[0] + kind, 2 * e[1] + kind));
          }
        }
      });
    for (size_t f = 0; f < c.Faces.size(); ++f)
    {
      const std::array<int, 3> t = VolumeSet::CapCorners(c, f, set[f]);
      // As drawn: light cap t0, t1, t2; dark cap t0, t2, t1 (VolumeBuilder::CapAndDark).
      const int order[2][3] = { { t[0], t[1], t[2] }, { t[0], t[2], t[1] } };
      for (int kind = 0; kind < 2; ++kind)
      {
        if (kept[f] >> kind & 1)
        {
          for (int k = 0; k < 3; ++k)
          {
            float v[4];
            const int id = 2 * order[kind][k] + kind;
            build.TablePoint(mesh, id, v);
            triangles.Put(v[0], v[1], v[2], v[3], id);
          }
        }
      }
    }
  }
  build.Outline.Build(triangles, gpuUncertain, mesh.Points.size());
  std::sort(skip.begin(), skip.end());
  skip.erase(std::unique(skip.begin(), skip.end()), skip.end());
  build.Outline.Skip.swap(skip);
  build.Outline.Shared = shared;
}

// One light's outline pixels (OutlinePixels): the kept part (VolumeOutline::Mark), then the
// cap interiors' edges (MarkOutline): an edge two caps of one set share is continuous
// unless the caps face the camera differently (or edge-on), the rule Mark applies to a pair.
void vtkPenumbraShadowVolumeShadows::Internals::MarkOutline(VolumeSet& vs, int width, int height)
{
  std::vector<unsigned char>& pixels = this->OutlinePixels;
  pixels.assign(static_cast<size_t>(width) * static_cast<size_t>(height), 0);
  vs.Outline.Mark(this->Projection, width, height, pixels);
  const Connectivity& mesh = this->Mesh;
  const std::vector<std::uint64_t>& shared = vs.Outline.Shared;
  auto project = [&](int id)
  {
    float v[4];
    vs.TablePoint(mesh, id, v);
    return Project(this->Projection, v);
  };
  std::vector<signed char> sides;
  for (size_t ci = 0; ci < mesh.Components.size(); ++ci)
  {
    const Connectivity::Component& c = mesh.Components[ci];
    const std::vector<signed char>& set = vs.Sets[ci];
    if (set.empty())
    {
      continue;
    }
    // Per face, the screen side of its light cap and of its dark cap, as drawn.
    sides.assign(2 * c.Faces.size(), 0);
    vtkSMPTools::For(0, static_cast<vtkIdType>(c.Faces.size()),
      [&](vtkIdType begin, vtkIdType end)
      {
        for (vtkIdType f = begin; f < end; ++f)
        {
          if (set[static_cast<size_t>(f)] == 0)
          {
            continue;
          }
          const std::array<int, 3> t =
            VolumeSet::CapCorners(c, static_cast<size_t>(f), set[static_cast<size_t>(f)]);
          sides[2 * static_cast<size_t>(f)] =
            Side(project(2 * t[0]), project(2 * t[1]), project(2 * t[2]));
          sides[2 * static_cast<size_t>(f) + 1] =
            Side(project(2 * t[0] + 1), project(2 * t[2] + 1), project(2 * t[1] + 1));
        }
      });
    c.ForEachEdge(
      [&](const std::array<int, 4>& e)
      {
        const signed char s0 = set[static_cast<size_t>(e[2])];
        const signed char s1 = e[3] >= 0 ? set[static_cast<size_t>(e[3])] : 0;
        if (s0 != s1 || s0 == 0)
        {
          return; // kept explicit
        }
        for (int kind = 0; kind < 2; ++kind)
        {
          const int a = 2 * e[0] + kind, b = 2 * e[1] + kind;
          const signed char side0 =
            sides[2 * static_cast<size_t>(e[2]) + static_cast<size_t>(kind)];
          const signed char side1 =
            sides[2 * static_cast<size_t>(e[3]) + static_cast<size_t>(kind)];
          if ((side0 == side1 && side0 != 0) ||
            std::binary_search(shared.begin(), shared.end(), VolumeOutline::Pair(a, b)))
          {
            continue; // continuous, or shared with explicit triangles: the kept part judges it
          }
          VolumeOutline::MarkSegment(project(a), project(b), width, height, pixels);
        }
      });
  }
}
