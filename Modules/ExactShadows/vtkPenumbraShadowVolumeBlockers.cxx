// vtkPenumbraShadowVolumeShadows: the casters that can block the rays of the samples the edge
// resolve traces, so that on large scenes the tracer holds an Embree scene of those alone.
//
// A triangle blocks the segment from sample x toward the light only if it meets the line
// through x along the light's direction. Projected along that line (orthographically for a
// directional light, centrally from a positional light's position onto the face of a cube
// around it), the blocking point lands where x lands, so the triangle's projected box holds
// x's projection. A grid of the traced samples' projections (each grown by a margin that
// covers the tracer's float32 rays and corners, see Margin) keeps every triangle whose
// projected box meets a marked cell: a superset of the blockers, which the tracer then
// decides with its own rules, the same answers as with every occluder.

#include "vtkPenumbraShadowVolumeInternals.h"

#include "vtkIdTypeArray.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraSceneTriangles.h"
#include "vtkSMPThreadLocal.h"
#include "vtkSMPTools.h"

#include <algorithm>
#include <cmath>

using namespace penumbra_shadow_volume;

namespace
{
// One projection of the samples: a directional light's plane, or one face of the cube around
// a positional light (points p with Sign * (p - L)[Axis] > 0).
struct BlockerView
{
  int Cells = 0; // per side
  int Axis = 0;
  double Sign = 1.0;
  bool Used = false;
  double Lo[2] = { VTK_DOUBLE_MAX, VTK_DOUBLE_MAX };
  double Hi[2] = { -VTK_DOUBLE_MAX, -VTK_DOUBLE_MAX };
  double Inv[2] = { 0, 0 };
  std::vector<int> Sum; // (Cells + 1)^2: marked cells in [0, x) x [0, y)

  int Cell(int a, double v) const
  {
    const double c = std::floor((v - this->Lo[a]) * this->Inv[a]);
    return c < 0.0 ? 0 : (c >= this->Cells ? this->Cells - 1 : static_cast<int>(c));
  }
  // Whether the box [u0, u1] meets a marked cell.
  bool Meets(const double u0[2], const double u1[2]) const
  {
    for (int a = 0; a < 2; ++a)
    {
      if (u1[a] < this->Lo[a] || u0[a] > this->Hi[a])
      {
        return false;
      }
    }
    const int x0 = this->Cell(0, u0[0]), x1 = this->Cell(0, u1[0]) + 1;
    const int y0 = this->Cell(1, u0[1]), y1 = this->Cell(1, u1[1]) + 1;
    const auto at = [&](int x, int y)
    { return this->Sum[static_cast<size_t>(y * (this->Cells + 1) + x)]; };
    return at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0) > 0;
  }
};

// The distance from p to the box [lo, hi].
double DistanceToBox(const double lo[3], const double hi[3], const Vec3& p)
{
  double gap = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    const double d = std::max({ lo[a] - p[a], p[a] - hi[a], 0.0 });
    gap += d * d;
  }
  return std::sqrt(gap);
}

// The projections of every traced sample and of every caster for one light.
struct BlockerFilter
{
  const VolumeLight& Light;
  double Radius = 0.0;    // largest |corner| of the rebased scene bounds
  double NearLight = 0.0; // positional: triangles closer than this to the light are kept
  Vec3 E1, E2;            // directional: the projection plane's axes
  BlockerView Views[6];   // directional: Views[0] alone

  explicit BlockerFilter(const VolumeLight& light)
    : Light(light)
  {
  }

  // The projection of p in `view` (positional: p must lie on the view's side of the light).
  void Project(const BlockerView& view, const Vec3& p, double u[2]) const
  {
    if (this->Light.Directional)
    {
      u[0] = glm::dot(p, this->E1);
      u[1] = glm::dot(p, this->E2);
      return;
    }
    const Vec3 v = p - this->Light.Position;
    const double depth = view.Sign * v[view.Axis];
    u[0] = v[(view.Axis + 1) % 3] / depth;
    u[1] = v[(view.Axis + 2) % 3] / depth;
  }

  // How far (projected units) a traced ray's blocker can land from its sample's projection.
  // The tracer's ray starts at float32(x) along a float32 unit direction and meets float32
  // corners: it strays from the exact line by at most 1.1e-7 |x| + 2e-7 t + 1.1e-7 R at
  // distance t. A directional ray's blockers lie within the scene (t below 4 R); a positional
  // one's blocker is at least NearLight from the light (nearer triangles are kept whole), so
  // the direction from the light strays by at most that error over NearLight, and a cube
  // face's coordinates (at most 1 in size) by at most 3 times that angle. The margin is ten
  // times those bounds. Negative: no margin can be proved (the filter gives up).
  double Margin(const Vec3& x) const
  {
    const double ax = std::sqrt(glm::dot(x, x));
    if (this->Light.Directional)
    {
      return 10.0 * (1.1e-7 * ax + 9.1e-7 * this->Radius);
    }
    const Vec3 v = x - this->Light.Position;
    const double error = 1.1e-7 * ax + 2e-7 * std::sqrt(glm::dot(v, v)) + 1.1e-7 * this->Radius;
    const double margin = 30.0 * error / this->NearLight;
    return margin < 0.25 ? margin : -1.0;
  }

  // Cells per side of a view's grid: fine enough that the marked cells hug the traced
  // samples' curves (outlines, terminators) on the largest scenes; a positional light may
  // use six views.
  int Cells() const { return this->Light.Directional ? 2048 : 1024; }

  bool Setup(const double bounds[6]);
  bool MarkSamples(const penumbra_light_views::FrameInputs& in, const unsigned char* traced);
  bool Keeps(const double tv[9]) const;
};

bool BlockerFilter::Setup(const double bounds[6])
{
  for (int corner = 0; corner < 8; ++corner)
  {
    const Vec3 q = { bounds[corner & 1], bounds[2 + ((corner >> 1) & 1)],
      bounds[4 + ((corner >> 2) & 1)] };
    this->Radius = std::max(this->Radius, std::sqrt(glm::dot(q, q)));
  }
  if (this->Light.Directional)
  {
    const Vec3 d = glm::normalize(this->Light.Direction);
    int least = 0;
    for (int a = 1; a < 3; ++a)
    {
      least = std::fabs(d[a]) < std::fabs(d[least]) ? a : least;
    }
    Vec3 axis(0.0);
    axis[least] = 1.0;
    this->E1 = glm::normalize(glm::cross(d, axis));
    this->E2 = glm::cross(d, this->E1);
    return std::isfinite(this->E1[0] + this->E1[1] + this->E1[2]);
  }
  const double lo[3] = { bounds[0], bounds[2], bounds[4] };
  const double hi[3] = { bounds[1], bounds[3], bounds[5] };
  this->NearLight = std::max(1e-3 * this->Radius, DistanceToBox(lo, hi, this->Light.Position));
  for (int f = 0; f < 6; ++f)
  {
    this->Views[f].Axis = f / 2;
    this->Views[f].Sign = f % 2 ? -1.0 : 1.0;
  }
  return this->NearLight > 0.0;
}

// The grids of the traced samples' projections, each grown by its margin. False when some
// sample cannot be placed (it sits on the light, or its margin cannot be proved).
bool BlockerFilter::MarkSamples(
  const penumbra_light_views::FrameInputs& in, const unsigned char* traced)
{
  struct Mark
  {
    int View;
    double U[2];
    double Margin;
  };
  std::vector<Mark> marks;
  for (vtkIdType s = 0; s < in.NumberOfSamples; ++s)
  {
    if (!traced[s])
    {
      continue;
    }
    const Vec3 x = { in.Positions[3 * s] + in.Shift[0], in.Positions[3 * s + 1] + in.Shift[1],
      in.Positions[3 * s + 2] + in.Shift[2] };
    Mark m;
    m.View = 0;
    if (!this->Light.Directional)
    {
      const Vec3 v = x - this->Light.Position;
      int axis = 0;
      for (int a = 1; a < 3; ++a)
      {
        axis = std::fabs(v[a]) > std::fabs(v[axis]) ? a : axis;
      }
      if (!(v[axis] != 0.0))
      {
        return false;
      }
      m.View = 2 * axis + (v[axis] < 0.0 ? 1 : 0);
    }
    m.Margin = this->Margin(x);
    if (m.Margin < 0.0)
    {
      return false;
    }
    BlockerView& view = this->Views[m.View];
    this->Project(view, x, m.U);
    view.Used = true;
    for (int a = 0; a < 2; ++a)
    {
      view.Lo[a] = std::min(view.Lo[a], m.U[a] - m.Margin);
      view.Hi[a] = std::max(view.Hi[a], m.U[a] + m.Margin);
    }
    marks.push_back(m);
  }
  const int N = this->Cells();
  for (BlockerView& view : this->Views)
  {
    if (view.Used)
    {
      view.Cells = N;
      for (int a = 0; a < 2; ++a)
      {
        view.Inv[a] = N / (view.Hi[a] - view.Lo[a]);
      }
      view.Sum.assign(static_cast<size_t>((N + 1) * (N + 1)), 0);
    }
  }
  // Each sample's square as a difference pattern in Sum, summed up into cover counts, then
  // into counts of covered cells.
  for (const Mark& m : marks)
  {
    BlockerView& view = this->Views[m.View];
    const int x0 = view.Cell(0, m.U[0] - m.Margin), x1 = view.Cell(0, m.U[0] + m.Margin) + 1;
    const int y0 = view.Cell(1, m.U[1] - m.Margin), y1 = view.Cell(1, m.U[1] + m.Margin) + 1;
    auto at = [&](int x, int y) -> int& { return view.Sum[static_cast<size_t>(y * (N + 1) + x)]; };
    ++at(x0, y0);
    --at(x1, y0);
    --at(x0, y1);
    ++at(x1, y1);
  }
  for (BlockerView& view : this->Views)
  {
    if (!view.Used)
    {
      continue;
    }
    std::vector<int> cover(static_cast<size_t>(N * N));
    for (int y = 0; y < N; ++y)
    {
      for (int x = 0; x < N; ++x)
      {
        const size_t i = static_cast<size_t>(y * (N + 1) + x);
        int c = view.Sum[i];
        c += x > 0 ? cover[static_cast<size_t>(y * N + x - 1)] : 0;
        c += y > 0 ? cover[static_cast<size_t>((y - 1) * N + x)] : 0;
        c -= x > 0 && y > 0 ? cover[static_cast<size_t>((y - 1) * N + x - 1)] : 0;
        cover[static_cast<size_t>(y * N + x)] = c;
      }
    }
    std::fill(view.Sum.begin(), view.Sum.end(), 0);
    for (int y = 1; y <= N; ++y)
    {
      for (int x = 1; x <= N; ++x)
      {
        view.Sum[static_cast<size_t>(y * (N + 1) + x)] =
          (cover[static_cast<size_t>((y - 1) * N + x - 1)] > 0 ? 1 : 0) +
          view.Sum[static_cast<size_t>((y - 1) * (N + 1) + x)] +
          view.Sum[static_cast<size_t>(y * (N + 1) + x - 1)] -
          view.Sum[static_cast<size_t>((y - 1) * (N + 1) + x - 1)];
      }
    }
  }
  return true;
}

// Whether the triangle (rebased corners) may block a traced sample.
bool BlockerFilter::Keeps(const double tv[9]) const
{
  const Vec3 c[3] = { { tv[0], tv[1], tv[2] }, { tv[3], tv[4], tv[5] }, { tv[6], tv[7], tv[8] } };
  if (!this->Light.Directional)
  {
    double lo[3], hi[3]; // the triangle's box
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = std::min({ c[0][a], c[1][a], c[2][a] });
      hi[a] = std::max({ c[0][a], c[1][a], c[2][a] });
    }
    if (DistanceToBox(lo, hi, this->Light.Position) < this->NearLight)
    {
      return true;
    }
  }
  for (const BlockerView& view : this->Views)
  {
    if (!view.Used)
    {
      continue;
    }
    if (!this->Light.Directional)
    {
      int ahead = 0;
      for (const Vec3& p : c)
      {
        ahead += view.Sign * (p[view.Axis] - this->Light.Position[view.Axis]) > 0.0 ? 1 : 0;
      }
      if (ahead == 0)
      {
        continue; // behind this face: no blocker of its samples
      }
      if (ahead < 3)
      {
        return true; // across the face's plane through the light: kept whole
      }
    }
    double u0[2] = { VTK_DOUBLE_MAX, VTK_DOUBLE_MAX }, u1[2] = { -VTK_DOUBLE_MAX, -VTK_DOUBLE_MAX };
    for (const Vec3& p : c)
    {
      double u[2];
      this->Project(view, p, u);
      for (int a = 0; a < 2; ++a)
      {
        u0[a] = std::min(u0[a], u[a]);
        u1[a] = std::max(u1[a], u[a]);
      }
    }
    if (view.Meets(u0, u1))
    {
      return true;
    }
  }
  return false;
}
}

// The tracer of the edge resolve restricted to the casters that can block this job's traced
// samples (`traced`, per sample), on scenes above the tracer's compact threshold, where a
// BVH of every caster would cost more memory than the rest of the technique; below it, or
// when no margin can be proved, the tracer keeps every occluder.
void vtkPenumbraShadowVolumeShadows::Internals::LimitBlockers(
  vtkPenumbraShadowVolumeShadows& self, const Group& g, const Job& job, const unsigned char* traced)
{
  vtkPenumbraReference* reference = self.Reference;
  const penumbra::SceneTriangles& triangles = g.Geometry->GetTriangles();
  if (this->Mesh.Casters <= reference->GetCompactAbove())
  {
    reference->SetOccluderSubset(nullptr);
    return;
  }
  // The same light, casters and traced samples (a still frame): the same subset.
  const penumbra_light_views::FrameInputs& in = *g.In;
  BlockerCache key;
  key.Key = job.VL.Key();
  key.Key.insert(key.Key.end(),
    { static_cast<double>(g.Geometry->GetCastersTime()), in.Shift[0], in.Shift[1], in.Shift[2] });
  for (vtkIdType s = 0; s < in.NumberOfSamples; ++s)
  {
    if (traced[s])
    {
      key.Samples.push_back(s);
      key.Positions.insert(key.Positions.end(), in.Positions + 3 * s, in.Positions + 3 * s + 3);
    }
  }
  const size_t slot = static_cast<size_t>(&job - g.Jobs.data());
  this->Blockers.resize(std::max(this->Blockers.size(), g.Jobs.size()));
  BlockerCache& cache = this->Blockers[slot];
  if (cache.Subset && cache.Key == key.Key && cache.Samples == key.Samples &&
    cache.Positions == key.Positions)
  {
    reference->SetOccluderSubset(cache.Subset);
    return;
  }
  BlockerFilter filter(job.VL);
  if (!filter.Setup(g.RebasedBounds) || !filter.MarkSamples(in, traced))
  {
    cache = BlockerCache();
    reference->SetOccluderSubset(nullptr);
    return;
  }
  vtkSMPThreadLocal<std::vector<vtkIdType>> kept;
  for (const penumbra::SceneTriangles::Block& block : triangles.GetBlocks())
  {
    vtkSMPTools::For(0, block.List->Size(),
      [&](vtkIdType begin, vtkIdType end)
      {
        std::vector<vtkIdType>& local = kept.Local();
        for (vtkIdType t = begin; t < end; ++t)
        {
          double tv[9];
          if (triangles.IsOccluderLocal(block, t))
          {
            triangles.GetLocal(block, t, tv);
            if (filter.Keeps(tv))
            {
              local.push_back(block.First + t);
            }
          }
        }
      });
  }
  std::vector<vtkIdType> ids;
  for (const std::vector<vtkIdType>& part : kept)
  {
    ids.insert(ids.end(), part.begin(), part.end());
  }
  std::sort(ids.begin(), ids.end());
  cache = std::move(key);
  cache.Subset = vtkSmartPointer<vtkIdTypeArray>::New();
  cache.Subset->SetNumberOfTuples(static_cast<vtkIdType>(ids.size()));
  std::copy(ids.begin(), ids.end(), cache.Subset->GetPointer(0));
  reference->SetOccluderSubset(cache.Subset);
}
