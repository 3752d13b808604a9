#include "vtkPenumbraSoftShadowMapShadows.h"
#include "vtkPenumbraStatistics.h"

#include "vtkFloatArray.h"
#include "vtkLight.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraCasterBuffers.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraGLPassState.h"
#include "vtkPenumbraLightViews.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraShadowMapShadows.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkSMPThreadLocal.h"
#include "vtkSMPTools.h"
#include "vtkShaderProgram.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtkWeakPointer.h"
#include "vtk_glew.h"

#include "vtkPenumbraShadowMapFS.h"
#include "vtkPenumbraShadowMapVS.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkPenumbraSoftShadowMapShadows);

using penumbra_light_views::View;

namespace
{
using penumbra::Clock;
using penumbra::ElapsedMs;

// A light sample's map is one perspective view; receivers farther than this from its axis
// are left out (counted as seen by that sample).
constexpr double MaxHalfAngleDegrees = 85.0;

// Slope-scaled bias stops growing here, as vtkPenumbraShadowMapShadows' does (0.057 degrees
// from grazing).
constexpr double MaxTangent = 1000.0;

// Discontinuities this close to the map border are the frustum's edges, not silhouettes
// (Brabec 2003, ch. 10, border guard band).
constexpr int GuardBand = 2;

// Floats per skin vertex (rebased x, y, z and the visibility) and per skin triangle.
constexpr int SkinVertex = 4;
constexpr int SkinTriangle = 3 * SkinVertex;

// The most light samples a light gets (16 along a line, 4 x 4 on a rectangle).
constexpr int MaxSamples = 16;

// One light sample: where it is, its view, its depth map and its visibility channel.
struct SampleMap
{
  double Apex[3] = { 0, 0, 0 };
  double Axes[3][3] = {};   // the view's right, up and forward axes
  View Camera;              // always perspective
  double InvFar = 1.0;      // 1 / Camera.Far
  std::vector<float> Depth; // Resolution^2, row 0 at the bottom: linear depth / Far
  // The same of every surface, casters or not, when some do not cast (else empty): the
  // receivers behind a silhouette, where its skin ends.
  std::vector<float> Surface;
  std::vector<float> Skins; // SkinTriangle floats per skin triangle, rebased

  const std::vector<float>& SurfaceDepth() const
  {
    return this->Surface.empty() ? this->Depth : this->Surface;
  }
};

// The light's elements: M sample indices each, in order around the element (2 for
// segments, 3 for triangles, 4 for grid cells), and the element polygon's edges in both
// directions. Channel (a, b) lives in a's map: the skins of b warped there.
struct LightElements
{
  int M = 2;
  std::vector<int> Index;
  std::vector<int> ChannelOf; // samples^2 entries: channel of (a, b), -1 when not adjacent
  std::vector<std::pair<int, int>> Channels;

  int Count() const { return static_cast<int>(this->Index.size()) / this->M; }
  int At(int e, int k) const { return this->Index[static_cast<size_t>(e * this->M + k)]; }

  void Link(int samples)
  {
    this->ChannelOf.assign(static_cast<size_t>(samples) * samples, -1);
    this->Channels.clear();
    for (int e = 0; e < this->Count(); ++e)
    {
      for (int k = 0; k < this->M; ++k)
      {
        for (int j = 1; j < this->M; ++j)
        {
          const int a = this->At(e, k), b = this->At(e, (k + j) % this->M);
          const bool edge = this->M < 4 || j != 2; // a cell's diagonals are not edges
          int& slot = this->ChannelOf[static_cast<size_t>(a) * samples + b];
          if (edge && slot < 0)
          {
            slot = static_cast<int>(this->Channels.size());
            this->Channels.emplace_back(a, b);
          }
        }
      }
    }
  }
};

// World position (rebased) of texel (ix, iy) of map m at its stored depth.
void Unproject(const SampleMap& m, int res, int ix, int iy, double out[3])
{
  const double s = (ix + 0.5) * 2.0 / res - 1.0;
  const double t = (iy + 0.5) * 2.0 / res - 1.0;
  const double w = m.SurfaceDepth()[static_cast<size_t>(iy) * res + ix] * m.Camera.Far;
  const double k = m.Camera.TanHalf;
  for (int c = 0; c < 3; ++c)
  {
    out[c] = m.Apex[c] + w * (m.Axes[2][c] + k * (s * m.Axes[0][c] + t * m.Axes[1][c]));
  }
}

// 3 x 3 Laplacian of the linear depth at texel i (not on the border), relative (Brabec 2003,
// ch. 10.1.4, with the threshold made relative to the depth): |L| / (3 d) is h at both sides
// of a straight step of relative height h, and small on planes and creases.
bool Discontinuous(const float* d, size_t i, int res, double threshold)
{
  double sum = 0.0;
  for (int dy = -1; dy <= 1; ++dy)
  {
    for (int dx = -1; dx <= 1; ++dx)
    {
      sum += d[i + static_cast<size_t>(dy * res + dx)];
    }
  }
  return std::fabs(sum - 9.0 * d[i]) > 3.0 * threshold * d[i];
}

// The skins of one map (Brabec 2003, ch. 10.1.1): per 2 x 2 texel cell that straddles a
// discontinuity, its two triangles that join near and far texels, unprojected, with
// visibility 0 at the near (occluder) and 1 at the far (receiver) vertices. Found on the map
// of every surface; a cell whose near side does not cast makes none.
std::vector<float> BuildSkins(const SampleMap& m, int res, double threshold)
{
  const float* d = m.SurfaceDepth().data();
  const float* casters = m.Depth.data();
  vtkSMPThreadLocal<std::vector<float>> local;
  vtkSMPTools::For(GuardBand, res - 1 - GuardBand,
    [&](vtkIdType y0, vtkIdType y1)
    {
      std::vector<float>& out = local.Local();
      for (int y = static_cast<int>(y0); y < y1; ++y)
      {
        for (int x = GuardBand; x < res - 1 - GuardBand; ++x)
        {
          const int cx[4] = { x, x + 1, x + 1, x };
          const int cy[4] = { y, y, y + 1, y + 1 };
          double lo = std::numeric_limits<double>::max(), hi = -lo;
          for (int k = 0; k < 4; ++k)
          {
            const size_t i = static_cast<size_t>(cy[k]) * res + cx[k];
            lo = std::min(lo, static_cast<double>(d[i]));
            hi = std::max(hi, static_cast<double>(d[i]));
          }
          // The jump first (cheap, rejects nearly every cell), then the Laplacian.
          bool marked = false;
          for (int k = 0; hi - lo > threshold * lo && k < 4 && !marked; ++k)
          {
            marked = Discontinuous(d, static_cast<size_t>(cy[k]) * res + cx[k], res, threshold);
          }
          if (!marked)
          {
            continue;
          }
          const double mid = 0.5 * (lo + hi);
          static const int corners[2][3] = { { 0, 1, 2 }, { 0, 2, 3 } };
          for (const auto& tri : corners)
          {
            int nearCount = 0;
            bool nearCasts = true;
            for (int k : tri)
            {
              const size_t i = static_cast<size_t>(cy[k]) * res + cx[k];
              nearCount += d[i] < mid ? 1 : 0;
              nearCasts = nearCasts && (d[i] >= mid || casters[i] <= d[i]);
            }
            if (nearCount == 0 || nearCount == 3 || !nearCasts)
            {
              continue; // all on one side: not part of the skin
            }
            for (int k : tri)
            {
              double p[3];
              Unproject(m, res, cx[k], cy[k], p);
              const bool isNear = d[static_cast<size_t>(cy[k]) * res + cx[k]] < mid;
              out.insert(out.end(),
                { static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]),
                  isNear ? 0.0f : 1.0f });
            }
          }
        }
      }
    });
  std::vector<float> skins;
  for (const std::vector<float>& part : local)
  {
    skins.insert(skins.end(), part.begin(), part.end());
  }
  return skins;
}

// A skin vertex in a destination map: texel-centred raster position, 1 / w and visibility.
struct RasterVertex
{
  double X, Y, InvW, V;
};

// Scan-converts one skin triangle into `dst` where it lies in front of the destination's
// real depth by more than `bias`; the nearest skin wins through `zbuf`, the real depth is
// never written (Brabec 2003, ch. 10: skins are only depth-tested). The depth is interpolated
// perspective-correctly, the visibility linearly in the destination's image (Gouraud without
// perspective correction): a skin covers exactly the penumbra behind it as the destination
// sees it, so for a receiver parallel to a linear light the value is linear across the
// penumbra, exactly Eq. 10.1 (perspective-correct interpolation would be linear along the
// skin instead, 0.1 off in the middle of the test edge's penumbra).
void RasterizeSkin(const RasterVertex v[3], const SampleMap& dst, int res, double bias,
  std::vector<float>& value, std::vector<float>& zbuf)
{
  const double area = (v[1].X - v[0].X) * (v[2].Y - v[0].Y) - (v[2].X - v[0].X) * (v[1].Y - v[0].Y);
  if (!(std::fabs(area) > 1e-12))
  {
    return;
  }
  const double yMin = std::min({ v[0].Y, v[1].Y, v[2].Y });
  const double yMax = std::max({ v[0].Y, v[1].Y, v[2].Y });
  const int y0 = std::max(0, static_cast<int>(std::ceil(yMin)));
  const int y1 = std::min(res - 1, static_cast<int>(std::floor(yMax)));
  const double invFar = 1.0 / dst.Camera.Far;
  for (int y = y0; y <= y1; ++y)
  {
    // The row's span: where the horizontal line crosses the triangle's edges.
    double xl = std::numeric_limits<double>::max(), xr = -xl;
    for (int e = 0; e < 3; ++e)
    {
      const RasterVertex& a = v[e];
      const RasterVertex& b = v[(e + 1) % 3];
      if ((y < a.Y && y < b.Y) || (y > a.Y && y > b.Y))
      {
        continue;
      }
      const double x = a.Y == b.Y ? a.X : a.X + (y - a.Y) * (b.X - a.X) / (b.Y - a.Y);
      xl = std::min({ xl, x, a.Y == b.Y ? b.X : x });
      xr = std::max({ xr, x, a.Y == b.Y ? b.X : x });
    }
    const int x0 = std::max(0, static_cast<int>(std::ceil(xl)));
    const int x1 = std::min(res - 1, static_cast<int>(std::floor(xr)));
    for (int x = x0; x <= x1; ++x)
    {
      const double l1 =
        ((x - v[0].X) * (v[2].Y - v[0].Y) - (v[2].X - v[0].X) * (y - v[0].Y)) / area;
      const double l2 =
        ((v[1].X - v[0].X) * (y - v[0].Y) - (x - v[0].X) * (v[1].Y - v[0].Y)) / area;
      const double l0 = 1.0 - l1 - l2;
      const double invW = l0 * v[0].InvW + l1 * v[1].InvW + l2 * v[2].InvW;
      if (!(invW > 0.0))
      {
        continue;
      }
      const double depth = invFar / invW;
      const size_t i = static_cast<size_t>(y) * res + x;
      if (!(depth < dst.SurfaceDepth()[i] - bias) || !(depth < zbuf[i]))
      {
        continue;
      }
      zbuf[i] = static_cast<float>(depth);
      const double vis = l0 * v[0].V + l1 * v[1].V + l2 * v[2].V;
      value[i] = static_cast<float>(std::min(1.0, std::max(0.0, vis)));
    }
  }
}

// Warps `skins` (another sample's) into `dst`: `value` gets the nearest skin's visibility per
// texel, -1 where no skin lies in front of the real geometry.
void WarpSkins(const std::vector<float>& skins, const SampleMap& dst, int res, double bias,
  std::vector<float>& value, std::vector<float>& zbuf)
{
  const size_t texels = static_cast<size_t>(res) * res;
  value.assign(texels, -1.0f);
  zbuf.assign(texels, std::numeric_limits<float>::max());
  const View& view = dst.Camera;
  for (size_t t = 0; t + SkinTriangle <= skins.size(); t += SkinTriangle)
  {
    RasterVertex v[3];
    bool inFront = true;
    for (int k = 0; k < 3; ++k)
    {
      const float* f = skins.data() + t + static_cast<size_t>(k) * SkinVertex;
      const double p[3] = { f[0], f[1], f[2] };
      const double w = view.Dot(3, p);
      inFront = inFront && w > view.NearW;
      const double iw = w > 0.0 ? 1.0 / w : 0.0;
      v[k] = { (view.Dot(0, p) * iw * 0.5 + 0.5) * res - 0.5,
        (view.Dot(1, p) * iw * 0.5 + 0.5) * res - 0.5, iw, f[3] };
    }
    if (inFront)
    {
      RasterizeSkin(v, dst, res, bias, value, zbuf);
    }
  }
}
// What one view sample's lookup found in one light sample's map.
struct SampleTest
{
  bool Lit = false;     // faces the light sample and passes its shadow test
  bool Blocked = false; // faces it but fails the shadow test
  double Facing = 0.0;  // normal . (light sample - view sample)
  vtkIdType Texel = -1; // in the map, -1 outside it
};

// The fraction of element edge a -> b a view sample sees, from the lit end a towards the
// unlit b: where b lies below the tangent plane the plane's crossing (exact), where b fails
// its shadow test the skin value of b in a's map (Brabec 2003, ch. 10.1.1: 0 at the
// occluder, 1 at the receiver), the smaller of both; 0.5 when b is blocked but no skin
// covers the sample.
double Split(const SampleTest* test, int a, int b, const std::vector<int>& channelOf, int samples,
  const std::vector<std::vector<float>>& values)
{
  double t = 1.0;
  if (!(test[b].Facing > 0.0))
  {
    t = test[a].Facing / (test[a].Facing - test[b].Facing);
  }
  if (test[b].Blocked)
  {
    const int c = channelOf[static_cast<size_t>(a) * samples + b];
    const float v = c >= 0 && test[a].Texel >= 0
      ? values[static_cast<size_t>(c)][static_cast<size_t>(test[a].Texel)]
      : -1.0f;
    t = std::min(t, v >= 0.0f ? static_cast<double>(v) : 0.5);
  }
  return t;
}

// The visible fraction of element e for one view sample (see the class description, step 5).
double ElementVisibility(const LightElements& parts, int e, const SampleTest* test, int samples,
  const std::vector<std::vector<float>>& values)
{
  const int m = parts.M;
  auto split = [&](int a, int b) { return Split(test, a, b, parts.ChannelOf, samples, values); };
  if (m == 3)
  {
    // Brabec 2003, ch. 10.1.3: each lit vertex carries 1/3, or the smallest skin value of the
    // other two in its map times 1/2.
    double sum = 0.0;
    for (int k = 0; k < 3; ++k)
    {
      const int a = parts.At(e, k);
      double v = 2.0;
      for (int j = 1; test[a].Lit && j < 3; ++j)
      {
        const int b = parts.At(e, (k + j) % 3);
        v = test[b].Lit ? v : std::min(v, split(a, b));
      }
      sum += !test[a].Lit ? 0.0 : (v <= 1.0 ? 0.5 * v : 1.0 / 3.0);
    }
    return sum;
  }
  if (m == 2)
  {
    const int a = parts.At(e, 0), b = parts.At(e, 1);
    return test[a].Lit ? (test[b].Lit ? 1.0 : split(a, b)) : (test[b].Lit ? split(b, a) : 0.0);
  }
  // A grid cell (Ying et al.'s variant, ch. 10.1.3): the polygon of its lit corners and the
  // split points of its edges between a lit and an unlit corner, in the unit square.
  static const double corner[4][2] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };
  double pts[8][2];
  int count = 0;
  for (int k = 0; k < 4; ++k)
  {
    const int a = parts.At(e, k), b = parts.At(e, (k + 1) % 4);
    const double* p = corner[k];
    const double* q = corner[(k + 1) % 4];
    if (test[a].Lit)
    {
      pts[count][0] = p[0];
      pts[count++][1] = p[1];
    }
    if (test[a].Lit != test[b].Lit)
    {
      const double t = test[a].Lit ? split(a, b) : 1.0 - split(b, a);
      pts[count][0] = p[0] + t * (q[0] - p[0]);
      pts[count++][1] = p[1] + t * (q[1] - p[1]);
    }
  }
  double area = 0.0;
  for (int k = 0; k < count; ++k)
  {
    const double* p = pts[k];
    const double* q = pts[(k + 1) % count];
    area += p[0] * q[1] - q[0] * p[1];
  }
  return std::min(1.0, 0.5 * std::fabs(area));
}

}

// Whether every sample of the block [x0, x1) x [y0, y1) (of a sample image `width` wide)
// has the prop of corner c[0] and lies on its plane: the same facet normal, and within a
// thousandth of the block's size of the plane through c[0]. Then the block holds one flat
// surface, and its corners' agreement on full light or umbra stands for its samples.
bool OnePlane(const penumbra_light_views::FrameInputs& in, const vtkIdType c[4], int x0, int y0,
  int x1, int y1, int width)
{
  const float* p0 = in.Positions + 3 * c[0];
  const float* n0 = in.Normals + 3 * c[0];
  double size = 0.0;
  for (int k = 1; k < 4; ++k)
  {
    const float* p = in.Positions + 3 * c[k];
    size = std::max(size,
      std::fabs(static_cast<double>(p[0]) - p0[0]) + std::fabs(static_cast<double>(p[1]) - p0[1]) +
        std::fabs(static_cast<double>(p[2]) - p0[2]));
  }
  const double tolerance = 1e-3 * size;
  for (int y = y0; y < y1; ++y)
  {
    for (int x = x0; x < x1; ++x)
    {
      const vtkIdType s = static_cast<vtkIdType>(y) * width + x;
      const float* p = in.Positions + 3 * s;
      const float* n = in.Normals + 3 * s;
      double along = 0.0, agree = 0.0;
      for (int k = 0; k < 3; ++k)
      {
        along += (static_cast<double>(p[k]) - p0[k]) * n0[k];
        agree += static_cast<double>(n[k]) * n0[k];
      }
      if (in.Props[s] != in.Props[c[0]] || !(agree > 0.9999) || !(std::fabs(along) <= tolerance))
      {
        return false;
      }
    }
  }
  return true;
}

struct vtkPenumbraSoftShadowMapShadows::Internals
{
  vtkWeakPointer<vtkOpenGLRenderWindow> Window;
  penumbra_casters::CasterBuffers Casters;
  penumbra_casters::CasterBuffers Surfaces; // every triangle, for the skins
  bool NeedSurfaces = false;                // some triangles do not cast

  Internals() { this->Surfaces.AllSurfaces = true; }

  vtkSmartPointer<vtkOpenGLFramebufferObject> FBO;
  vtkSmartPointer<vtkTextureObject> DepthTexture;
  int MapSize = 0;
  // One light's maps, elements and channels, kept while its key (light, scene, settings and,
  // when the maps could not be fitted to the scene, the view samples) stays the same.
  struct LightState
  {
    vtkWeakPointer<vtkLight> Light;
    std::vector<double> Key;
    std::vector<SampleMap> Maps;
    LightElements Parts;
    std::vector<std::vector<float>> Values; // per channel of Parts, -1 where no skin
  };
  std::vector<LightState> Cache;
  LightState* Now = nullptr; // the light being computed
  bool FitScene = false;     // FIT_SCENE asked for
  // Point, spot and directional lights: hard shadow maps.
  vtkNew<vtkPenumbraShadowMapShadows> Hard;

  void Release(vtkWindow* window)
  {
    if (this->Window && (!window || window == this->Window))
    {
      this->Window->MakeCurrent();
      this->Casters.Release();
      this->Surfaces.Release();
      if (this->DepthTexture)
      {
        this->DepthTexture->ReleaseGraphicsResources(this->Window);
      }
      if (this->FBO)
      {
        this->FBO->ReleaseGraphicsResources(this->Window);
      }
    }
    this->Casters.Forget();
    this->Surfaces.Forget();
    this->DepthTexture = nullptr;
    this->FBO = nullptr;
    this->MapSize = 0;
    this->Window = nullptr;
    this->Cache.clear();
    this->Now = nullptr;
  }

  bool UpdateCasters(vtkOpenGLRenderWindow* win, vtkPenumbraSceneGeometry* geometry);
  void PlaceSamples(
    vtkPenumbraSoftShadowMapShadows* self, vtkPenumbraAreaLight* area, const double origin[3]);
  bool FitViews(vtkPenumbraAreaLight* area, const penumbra_light_views::FrameInputs& in);
  bool FitToScene(double f[3], std::vector<double>& widest);
  void FitToSamples(const penumbra_light_views::FrameInputs& in, double f[3],
    std::vector<double>& widest, double box[6]);
  std::vector<double> MapKey(vtkPenumbraSoftShadowMapShadows* self, vtkPenumbraAreaLight* area,
    vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, bool sceneFit);
  bool RenderMaps(vtkPenumbraSoftShadowMapShadows* self, std::string& error);
  void BuildChannels(vtkPenumbraSoftShadowMapShadows* self);
  void Lookup(vtkPenumbraSoftShadowMapShadows* self, const penumbra_light_views::FrameInputs& in,
    int width, int rows, bool anyCaster, float* vis);
  template <typename One>
  void LookupBlocks(const penumbra_light_views::FrameInputs& in, int width, int rows, int block,
    const One& one, float* vis);
  static SampleTest Test(vtkPenumbraSoftShadowMapShadows* self, const SampleMap& m,
    const double p[3], const double nrm[3], bool anyCaster, int res);
};

//------------------------------------------------------------------------------
vtkPenumbraSoftShadowMapShadows::vtkPenumbraSoftShadowMapShadows()
  : Impl(new Internals)
{
}

//------------------------------------------------------------------------------
vtkPenumbraSoftShadowMapShadows::~vtkPenumbraSoftShadowMapShadows()
{
  this->Impl->Release(nullptr);
}

//------------------------------------------------------------------------------
void vtkPenumbraSoftShadowMapShadows::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Impl->Release(window);
  this->Impl->Hard->ReleaseGraphicsResources(window);
}

//------------------------------------------------------------------------------
// The casters as GL buffers for this window (uploaded when they changed); false without any.
bool vtkPenumbraSoftShadowMapShadows::Internals::UpdateCasters(
  vtkOpenGLRenderWindow* win, vtkPenumbraSceneGeometry* geometry)
{
  win->MakeCurrent();
  if (this->Window && this->Window != win)
  {
    this->Release(nullptr);
  }
  this->Window = win;
  this->Casters.Update(geometry);
  this->Surfaces.Update(geometry, false); // on the GPU only when some triangles do not cast
  this->NeedSurfaces = this->Surfaces.VertexCount > this->Casters.VertexCount;
  this->Surfaces.Update(geometry, this->NeedSurfaces);
  return this->Casters.VertexCount > 0;
}

//------------------------------------------------------------------------------
// Point (x, y) of the square [-1/2, 1/2]^2 on the disc of diameter `diameter` (Shirley & Chiu
// 1997, "A low distortion map between disk and square"): the square's rings become the disc's,
// so the grid keeps its cells and its outer ring lies on the rim.
namespace
{
void ConcentricDisc(double x, double y, double diameter, double& a, double& b)
{
  const double sx = 2.0 * x, sy = 2.0 * y; // [-1, 1]^2
  if (sx == 0.0 && sy == 0.0)
  {
    a = b = 0.0;
    return;
  }
  const double quarter = 0.25 * vtkMath::Pi();
  const bool wide = std::fabs(sx) > std::fabs(sy);
  const double r = wide ? sx : sy;
  const double phi = wide ? quarter * (sy / sx) : 2.0 * quarter - quarter * (sx / sy);
  a = 0.5 * diameter * r * std::cos(phi);
  b = 0.5 * diameter * r * std::sin(phi);
}
}

//------------------------------------------------------------------------------
// The light samples (rebased) and the elements that share them: a line's segments between
// adjacent samples (Brabec 2003, ch. 10.1.2), a rectangle grid's cells (Ying et al.'s
// polygon variant in ch. 10.1.3) or the cells split in two triangles (ch. 10.1.3).
void vtkPenumbraSoftShadowMapShadows::Internals::PlaceSamples(
  vtkPenumbraSoftShadowMapShadows* self, vtkPenumbraAreaLight* area, const double origin[3])
{
  double centre[3], u[3], v[3], n[3];
  area->GetCentre(centre);
  area->GetAxes(u, v, n);
  const bool line = area->GetShape() == vtkPenumbraAreaLight::Line;
  const bool disc = area->GetShape() == vtkPenumbraAreaLight::Disc;
  const int k = line ? self->NumberOfLineSamples : self->GridSamples;
  const int rows = line ? 1 : k;
  this->Now->Maps.resize(static_cast<size_t>(k * rows));
  for (int j = 0; j < rows; ++j)
  {
    for (int i = 0; i < k; ++i)
    {
      double a = (static_cast<double>(i) / (k - 1) - 0.5) * area->GetWidth();
      double b = (static_cast<double>(j) / (k - 1) - 0.5) * area->GetExtentV();
      if (disc)
      {
        ConcentricDisc(static_cast<double>(i) / (k - 1) - 0.5,
          static_cast<double>(j) / (k - 1) - 0.5, area->GetWidth(), a, b);
      }
      SampleMap& m = this->Now->Maps[static_cast<size_t>(j * k + i)];
      for (int c = 0; c < 3; ++c)
      {
        m.Apex[c] = (centre[c] - origin[c]) + a * u[c] + b * v[c];
      }
    }
  }
  this->Now->Parts = LightElements();
  const bool triangles = self->Elements == ELEMENTS_TRIANGLES;
  this->Now->Parts.M = line ? 2 : (triangles ? 3 : 4);
  for (int j = 0; j < std::max(1, rows - 1); ++j)
  {
    for (int i = 0; i + 1 < k; ++i)
    {
      const int c0 = j * k + i;
      auto& index = this->Now->Parts.Index;
      if (line)
      {
        index.insert(index.end(), { c0, c0 + 1 });
      }
      else if (triangles)
      {
        index.insert(index.end(), { c0, c0 + 1, c0 + k + 1, c0, c0 + k + 1, c0 + k });
      }
      else
      {
        index.insert(index.end(), { c0, c0 + 1, c0 + k + 1, c0 + k });
      }
    }
  }
  this->Now->Parts.Link(static_cast<int>(this->Now->Maps.size()));
}

//------------------------------------------------------------------------------
// One perspective view per light sample along the emission direction (flipped when the scene
// or the receivers lie behind the light), its square field of view fitted to the whole scene
// when every corner of its box lies within MaxHalfAngleDegrees of each sample's axis (the
// maps then do not depend on the view and are kept while the camera moves), else to every
// view sample in front of it (at most MaxHalfAngleDegrees); Far reaches the farthest surface
// or receiver. True when fitted to the scene.
bool vtkPenumbraSoftShadowMapShadows::Internals::FitViews(
  vtkPenumbraAreaLight* area, const penumbra_light_views::FrameInputs& in)
{
  double u[3], v[3], f[3];
  area->GetAxes(u, v, f);
  std::vector<double> widest;
  double box[6];
  std::copy(this->Surfaces.Bounds, this->Surfaces.Bounds + 6, box);
  const bool scene = this->FitScene && this->FitToScene(f, widest);
  if (!scene)
  {
    area->GetAxes(u, v, f);
    this->FitToSamples(in, f, widest, box);
  }
  double r[3], up[3];
  penumbra_light_views::Basis(f, r, up);
  const double maxTan = std::tan(vtkMath::RadiansFromDegrees(MaxHalfAngleDegrees));
  for (size_t m = 0; m < this->Now->Maps.size(); ++m)
  {
    SampleMap& map = this->Now->Maps[m];
    map.Camera =
      penumbra_light_views::PerspectiveView(map.Apex, f, std::min(maxTan, 1.02 * widest[m]), box);
    map.InvFar = 1.0 / map.Camera.Far;
    std::copy(r, r + 3, map.Axes[0]);
    std::copy(up, up + 3, map.Axes[1]);
    std::copy(f, f + 3, map.Axes[2]);
  }
  return scene;
}

//------------------------------------------------------------------------------
// The scene fit of FitViews: per map the widest tangent to a corner of the box of every
// surface; false when a corner is not well in front of a sample (the emission direction `f`
// is flipped towards the box first).
bool vtkPenumbraSoftShadowMapShadows::Internals::FitToScene(
  double f[3], std::vector<double>& widest)
{
  const double* b = this->Surfaces.Bounds;
  if (this->Surfaces.VertexCount == 0)
  {
    return false;
  }
  // The axis from the light's centre to the box's: the narrowest cone over the scene.
  double toBox[3] = { 0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]), 0.5 * (b[4] + b[5]) };
  for (const SampleMap& m : this->Now->Maps)
  {
    for (int c = 0; c < 3; ++c)
    {
      toBox[c] -= m.Apex[c] / this->Now->Maps.size();
    }
  }
  if (!(vtkMath::Normalize(toBox) > 0.0))
  {
    return false;
  }
  std::copy(toBox, toBox + 3, f);
  double r[3], up[3];
  penumbra_light_views::Basis(f, r, up);
  const double maxTan = std::tan(vtkMath::RadiansFromDegrees(MaxHalfAngleDegrees));
  widest.assign(this->Now->Maps.size(), std::tan(vtkMath::RadiansFromDegrees(1.0)));
  for (size_t m = 0; m < this->Now->Maps.size(); ++m)
  {
    const double* a = this->Now->Maps[m].Apex;
    for (int i = 0; i < 8; ++i)
    {
      const double d[3] = { b[i & 1] - a[0], b[2 + ((i >> 1) & 1)] - a[1],
        b[4 + ((i >> 2) & 1)] - a[2] };
      const double w = vtkMath::Dot(d, f);
      const double lateral =
        std::max(std::fabs(vtkMath::Dot(d, r)), std::fabs(vtkMath::Dot(d, up)));
      if (!(w > 0.0) || !(1.02 * lateral < maxTan * w))
      {
        return false;
      }
      widest[m] = std::max(widest[m], lateral / w);
    }
  }
  return true;
}

//------------------------------------------------------------------------------
// The view-sample fit of FitViews: `f` flipped towards most receivers, per map the widest
// tangent to a receiver in front of it, and `box` grown by the receivers' bounds.
void vtkPenumbraSoftShadowMapShadows::Internals::FitToSamples(
  const penumbra_light_views::FrameInputs& in, double f[3], std::vector<double>& widest,
  double box[6])
{
  const size_t count = this->Now->Maps.size();
  // Per thread: the receivers' bounds, the signed count of their sides along f, and per map
  // the largest |lateral| / depth.
  struct Fit
  {
    double Box[6] = { 1e300, -1e300, 1e300, -1e300, 1e300, -1e300 };
    double Side = 0.0;
    std::vector<double> Tan;
  };
  const double* apex0 = this->Now->Maps[0].Apex;
  auto point = [&](vtkIdType s, double p[3])
  {
    for (int c = 0; c < 3; ++c)
    {
      p[c] = static_cast<double>(in.Positions[3 * s + c]) + in.Shift[c];
    }
    return in.Props[s] >= 0 && std::isfinite(p[0] + p[1] + p[2]);
  };
  vtkSMPThreadLocal<Fit> local;
  vtkSMPTools::For(0, in.NumberOfSamples,
    [&](vtkIdType s0, vtkIdType s1)
    {
      Fit& fit = local.Local();
      for (vtkIdType s = s0; s < s1; ++s)
      {
        double p[3];
        for (int c = 0; point(s, p) && c < 3; ++c)
        {
          fit.Box[2 * c] = std::min(fit.Box[2 * c], p[c]);
          fit.Box[2 * c + 1] = std::max(fit.Box[2 * c + 1], p[c]);
          const double d = p[c] - apex0[c];
          fit.Side +=
            c == 2 ? (vtkMath::Dot(p, f) - vtkMath::Dot(apex0, f) > 0.0 ? 1.0 : -1.0) : 0.0;
          (void)d;
        }
      }
    });
  double side = 0.0;
  for (const Fit& fit : local)
  {
    for (int c = 0; c < 3; ++c)
    {
      box[2 * c] = std::min(box[2 * c], fit.Box[2 * c]);
      box[2 * c + 1] = std::max(box[2 * c + 1], fit.Box[2 * c + 1]);
    }
    side += fit.Side;
  }
  if (side < 0.0)
  {
    vtkMath::MultiplyScalar(f, -1.0);
  }
  double r[3], up[3];
  penumbra_light_views::Basis(f, r, up);
  vtkSMPThreadLocal<Fit> tangents;
  vtkSMPTools::For(0, in.NumberOfSamples,
    [&](vtkIdType s0, vtkIdType s1)
    {
      Fit& fit = tangents.Local();
      fit.Tan.resize(count, 0.0);
      for (vtkIdType s = s0; s < s1; ++s)
      {
        double p[3];
        for (size_t m = 0; point(s, p) && m < count; ++m)
        {
          const double* a = this->Now->Maps[m].Apex;
          const double d[3] = { p[0] - a[0], p[1] - a[1], p[2] - a[2] };
          const double w = vtkMath::Dot(d, f);
          const double lateral =
            std::max(std::fabs(vtkMath::Dot(d, r)), std::fabs(vtkMath::Dot(d, up)));
          fit.Tan[m] = w > 0.0 ? std::max(fit.Tan[m], lateral / w) : fit.Tan[m];
        }
      }
    });
  widest.assign(count, std::tan(vtkMath::RadiansFromDegrees(1.0)));
  for (const Fit& fit : tangents)
  {
    for (size_t m = 0; m < fit.Tan.size(); ++m)
    {
      widest[m] = std::max(widest[m], fit.Tan[m]);
    }
  }
}

//------------------------------------------------------------------------------
// Every light sample's depth map with shadowmap's programs (linear float depth, depth clamp,
// Brabec 2003, ch. 4.1), read back for the skins and the lookup.
bool vtkPenumbraSoftShadowMapShadows::Internals::RenderMaps(
  vtkPenumbraSoftShadowMapShadows* self, std::string& error)
{
  vtkOpenGLRenderWindow* win = this->Window;
  vtkShaderProgram* program =
    win->GetShaderCache()->ReadyShaderProgram(vtkPenumbraShadowMapVS, vtkPenumbraShadowMapFS, "");
  if (!program || !program->GetCompiled())
  {
    error = "the shadow map shaders do not compile or link on this OpenGL implementation";
    return false;
  }
  const int res = self->Resolution;
  if (!this->FBO || this->MapSize != res)
  {
    this->FBO = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
    this->FBO->SetContext(win);
    this->DepthTexture = vtkSmartPointer<vtkTextureObject>::New();
    this->DepthTexture->SetContext(win);
    this->DepthTexture->AllocateDepth(res, res, vtkTextureObject::Float32);
    this->MapSize = res;
  }
  vtkOpenGLState* ostate = win->GetState();
  penumbra_gl::MapRenderState state(ostate, this->FBO, res, false);
  this->FBO->AddDepthAttachment(this->DepthTexture);
  ostate->vtkglDrawBuffer(GL_NONE);
  ostate->vtkglReadBuffer(GL_NONE);
  program->SetUniformi("peel", 0);
  program->SetUniformi("perspective", 1);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  for (auto* buffers : { &this->Casters, &this->Surfaces })
  {
    if (buffers == &this->Surfaces && !this->NeedSurfaces)
    {
      break;
    }
    buffers->Bind(program);
    for (SampleMap& m : this->Now->Maps)
    {
      float matrix[16];
      m.Camera.ToFloatMatrix(matrix);
      program->SetUniformMatrix4x4("lightMatrix", matrix);
      program->SetUniformf("invFar", static_cast<float>(1.0 / m.Camera.Far));
      const GLfloat one = 1.0f;
      glClearBufferfv(GL_DEPTH, 0, &one);
      buffers->Draw();
      std::vector<float>& target = buffers == &this->Casters ? m.Depth : m.Surface;
      target.resize(static_cast<size_t>(res) * res);
      glReadPixels(0, 0, res, res, GL_DEPTH_COMPONENT, GL_FLOAT, target.data());
    }
  }
  for (SampleMap& m : this->Now->Maps)
  {
    m.Surface.resize(this->NeedSurfaces ? m.Surface.size() : 0);
  }
  glBindVertexArray(0);
  return true;
}

//------------------------------------------------------------------------------
// Skins per map, and per element edge (a, b) the skins of b warped into a's map (see the
// class description, steps 3-4).
void vtkPenumbraSoftShadowMapShadows::Internals::BuildChannels(
  vtkPenumbraSoftShadowMapShadows* self)
{
  const int res = self->Resolution;
  self->NumberOfSkins = 0;
  for (SampleMap& m : this->Now->Maps)
  {
    m.Skins = BuildSkins(m, res, self->Threshold);
    self->NumberOfSkins += static_cast<vtkIdType>(m.Skins.size() / SkinTriangle);
  }
  const auto& channels = this->Now->Parts.Channels;
  this->Now->Values.resize(channels.size());
  vtkSMPThreadLocal<std::vector<float>> zbuf;
  vtkSMPTools::For(0, static_cast<vtkIdType>(channels.size()),
    [&](vtkIdType c0, vtkIdType c1)
    {
      for (vtkIdType c = c0; c < c1; ++c)
      {
        const auto& edge = channels[static_cast<size_t>(c)];
        WarpSkins(this->Now->Maps[static_cast<size_t>(edge.second)].Skins,
          this->Now->Maps[static_cast<size_t>(edge.first)], res, self->Bias,
          this->Now->Values[static_cast<size_t>(c)], zbuf.Local());
      }
    });
}

//------------------------------------------------------------------------------
// Per view sample: the shadow test and the facing rule per light sample (a light sample on
// or below the tangent plane counts as occluded, as the reference's TraceAreaSample counts
// it), then the elements' visible fractions, averaged.
void vtkPenumbraSoftShadowMapShadows::Internals::Lookup(vtkPenumbraSoftShadowMapShadows* self,
  const penumbra_light_views::FrameInputs& in, int width, int rows, bool anyCaster, float* vis)
{
  const int res = self->Resolution;
  const int samples = static_cast<int>(this->Now->Maps.size());
  const bool off = in.Light.Off;
  // One view sample: background -1, light off 1, else the elements' visible fractions.
  auto one = [&](vtkIdType s) -> float
  {
    double p[3], nrm[3];
    for (int c = 0; c < 3; ++c)
    {
      p[c] = static_cast<double>(in.Positions[3 * s + c]) + in.Shift[c];
      nrm[c] = in.Normals[3 * s + c];
    }
    if (in.Props[s] < 0 || !std::isfinite(p[0] + p[1] + p[2] + nrm[0] + nrm[1] + nrm[2]))
    {
      return -1.0f;
    }
    if (off)
    {
      return 1.0f;
    }
    SampleTest test[MaxSamples];
    for (int i = 0; i < samples; ++i)
    {
      test[i] = this->Test(self, this->Now->Maps[static_cast<size_t>(i)], p, nrm, anyCaster, res);
    }
    double sum = 0.0;
    for (int e = 0; e < this->Now->Parts.Count(); ++e)
    {
      sum += ElementVisibility(this->Now->Parts, e, test, samples, this->Now->Values);
    }
    return static_cast<float>(std::min(1.0, std::max(0.0, sum / this->Now->Parts.Count())));
  };
  const int block = self->Block;
  if (block <= 1 || off || !anyCaster || width <= 0 || rows <= 0 ||
    static_cast<vtkIdType>(width) * rows != in.NumberOfSamples)
  {
    vtkSMPTools::For(0, in.NumberOfSamples,
      [&](vtkIdType s0, vtkIdType s1)
      {
        for (vtkIdType s = s0; s < s1; ++s)
        {
          vis[s] = one(s);
        }
      });
    return;
  }
  this->LookupBlocks(in, width, rows, block, one, vis);
}

//------------------------------------------------------------------------------
// The blocked lookup of SetBlock(): the lattice of block corners first, then per block
// either the corners' common value (full light or umbra, every sample on the corners'
// plane) or a lookup per sample.
template <typename One>
void vtkPenumbraSoftShadowMapShadows::Internals::LookupBlocks(
  const penumbra_light_views::FrameInputs& in, int width, int rows, int block, const One& one,
  float* vis)
{
  const int bw = (width + block - 1) / block, bh = (rows + block - 1) / block;
  auto corner = [&](int bx, int by)
  {
    return static_cast<vtkIdType>(std::min(by * block, rows - 1)) * width +
      std::min(bx * block, width - 1);
  };
  std::vector<float> lattice(static_cast<size_t>(bw + 1) * (bh + 1));
  vtkSMPTools::For(0, static_cast<vtkIdType>(lattice.size()),
    [&](vtkIdType l0, vtkIdType l1)
    {
      for (vtkIdType l = l0; l < l1; ++l)
      {
        lattice[static_cast<size_t>(l)] =
          one(corner(static_cast<int>(l % (bw + 1)), static_cast<int>(l / (bw + 1))));
      }
    });
  vtkSMPTools::For(0, static_cast<vtkIdType>(bw) * bh,
    [&](vtkIdType b0, vtkIdType b1)
    {
      for (vtkIdType b = b0; b < b1; ++b)
      {
        const int bx = static_cast<int>(b % bw), by = static_cast<int>(b / bw);
        const int x1 = std::min(width, (bx + 1) * block), y1 = std::min(rows, (by + 1) * block);
        const float v = lattice[static_cast<size_t>(by) * (bw + 1) + bx];
        const vtkIdType c[4] = { corner(bx, by), corner(bx + 1, by), corner(bx, by + 1),
          corner(bx + 1, by + 1) };
        bool uniform = (v == 0.0f || v == 1.0f) &&
          v == lattice[static_cast<size_t>(by) * (bw + 1) + bx + 1] &&
          v == lattice[static_cast<size_t>(by + 1) * (bw + 1) + bx] &&
          v == lattice[static_cast<size_t>(by + 1) * (bw + 1) + bx + 1];
        for (int k = 1; uniform && k < 4; ++k)
        {
          uniform = in.Props[c[k]] == in.Props[c[0]];
        }
        uniform = uniform && OnePlane(in, c, bx * block, by * block, x1, y1, width);
        for (int y = by * block; y < y1; ++y)
        {
          for (int x = bx * block; x < x1; ++x)
          {
            const vtkIdType s = static_cast<vtkIdType>(y) * width + x;
            vis[s] = uniform ? v : one(s);
          }
        }
      }
    });
}

//------------------------------------------------------------------------------
// One view sample p (normal nrm) against one light sample's map: facing, then the shadow
// test with vtkPenumbraShadowMapShadows' bias (constant + slope-scaled). Outside the map
// (or without casters) nothing blocks it.
SampleTest vtkPenumbraSoftShadowMapShadows::Internals::Test(vtkPenumbraSoftShadowMapShadows* self,
  const SampleMap& m, const double p[3], const double nrm[3], bool anyCaster, int res)
{
  SampleTest test;
  const double toLight[3] = { m.Apex[0] - p[0], m.Apex[1] - p[1], m.Apex[2] - p[2] };
  test.Facing = vtkMath::Dot(nrm, toLight);
  // The light sample's perspective projection (View::Project with one division instead of
  // three: this runs four times per view sample).
  const View& view = m.Camera;
  const double w = view.Dot(3, p);
  const double inv = 1.0 / w;
  const double ms = view.Dot(0, p) * inv, mt = view.Dot(1, p) * inv;
  if (!(test.Facing > 0.0) || !anyCaster || !(w > 0.0) || !(std::fabs(ms) < 1.0) ||
    !(std::fabs(mt) < 1.0))
  {
    test.Lit = test.Facing > 0.0;
    return test;
  }
  const double depth = w * m.InvFar;
  const int ix = std::min(res - 1, static_cast<int>((ms * 0.5 + 0.5) * res));
  const int iy = std::min(res - 1, static_cast<int>((mt * 0.5 + 0.5) * res));
  test.Texel = static_cast<vtkIdType>(iy) * res + ix;
  // Blocked when the stored depth lies below depth - Bias - slope * min(MaxTangent, tan).
  // The angle matters only when the stored depth falls inside the slope term's room: then,
  // with T = room / slope and c the cosine, min(MaxTangent, tan) < T exactly when
  // c^2 (1 + T^2) > 1 (T <= MaxTangent there), so no square root or division per sample.
  const double footprint = 2.0 * depth * m.Camera.TanHalf / res; // over Far
  const double slope = self->SlopeBias * footprint;
  const double room = depth - self->Bias - m.Depth[static_cast<size_t>(test.Texel)];
  if (!(room > 0.0))
  {
    test.Blocked = false;
  }
  else if (!(slope > 0.0) || room > slope * MaxTangent)
  {
    test.Blocked = true;
  }
  else
  {
    const double t = room / slope;
    const double cosine2 =
      test.Facing * test.Facing / (vtkMath::Dot(toLight, toLight) * vtkMath::Dot(nrm, nrm));
    test.Blocked = cosine2 * (1.0 + t * t) > 1.0;
  }
  test.Lit = !test.Blocked;
  return test;
}

//------------------------------------------------------------------------------
// What a light's maps and channels depend on: the light (its settings and motion), the
// scene's triangles and flags, this technique's settings, and the view samples when the maps
// were fitted to them.
std::vector<double> vtkPenumbraSoftShadowMapShadows::Internals::MapKey(
  vtkPenumbraSoftShadowMapShadows* self, vtkPenumbraAreaLight* area,
  vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, bool sceneFit)
{
  vtkMatrix4x4* transform = area->GetTransformMatrix();
  return { static_cast<double>(area->GetMTime()),
    transform ? static_cast<double>(transform->GetMTime()) : 0.0,
    static_cast<double>(geometry->GetCastersTime()), static_cast<double>(self->Resolution),
    static_cast<double>(self->NumberOfLineSamples), static_cast<double>(self->GridSamples),
    static_cast<double>(self->Elements), self->Threshold, self->Bias,
    static_cast<double>(self->Fit), sceneFit ? 0.0 : static_cast<double>(samples->GetMTime()) };
}

//------------------------------------------------------------------------------
// Brabec 2003, ch. 10 for one area or linear light: inputs, light samples, their maps, the
// skins and channels, the lookup. Other lights go to the hard shadow maps.
int vtkPenumbraSoftShadowMapShadows::ComputeVisibility(vtkRenderer* renderer,
  vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, vtkLight* light,
  vtkFloatArray* visibility)
{
  const auto start = Clock::now();
  Internals& impl = *this->Impl;
  auto* area = vtkPenumbraAreaLight::SafeDownCast(light);
  if (light && !area)
  {
    impl.Hard->SetResolution(this->Resolution);
    impl.Hard->SetBias(this->Bias);
    impl.Hard->SetSlopeBias(this->SlopeBias);
    const int ok = impl.Hard->ComputeVisibility(renderer, geometry, samples, light, visibility);
    this->LastTimeMs = ElapsedMs(start);
    return ok;
  }
  penumbra_light_views::FrameInputs in;
  std::string error;
  if (!in.Read(renderer, geometry, samples, light, visibility, error, true))
  {
    PENUMBRA_FAIL("soft shadow maps: " << error);
  }
  const std::string problem = area->GetValidityMessage();
  if (!problem.empty())
  {
    PENUMBRA_FAIL("soft shadow maps: invalid area light: " << problem);
  }
  this->MapTimeMs = this->SkinTimeMs = this->LookupTimeMs = 0.0;
  const bool anyCaster = !in.Light.Off && impl.UpdateCasters(in.Window, geometry);
  impl.Now = &penumbra_light_views::LightCacheEntry(impl.Cache, light);
  impl.FitScene = this->Fit == FIT_SCENE;
  impl.PlaceSamples(this, area, in.GeometryOrigin);
  this->NumberOfMaps = static_cast<int>(impl.Now->Maps.size());
  visibility->SetNumberOfComponents(1);
  visibility->SetNumberOfTuples(in.NumberOfSamples);
  float* vis = in.NumberOfSamples ? visibility->GetPointer(0) : nullptr;
  if (anyCaster && in.NumberOfSamples > 0)
  {
    const auto mapStart = Clock::now();
    const bool sceneFit = impl.FitViews(area, in);
    std::vector<double> key = impl.MapKey(this, area, geometry, samples, sceneFit);
    if (key != impl.Now->Key)
    {
      impl.Now->Key.clear();
      if (!impl.RenderMaps(this, error))
      {
        PENUMBRA_FAIL("soft shadow maps: " << error);
      }
      this->MapTimeMs = ElapsedMs(mapStart);
      const auto skinStart = Clock::now();
      impl.BuildChannels(this);
      this->SkinTimeMs = ElapsedMs(skinStart);
      impl.Now->Key = std::move(key);
      ++this->NumberOfBuilds;
    }
  }
  const auto lookupStart = Clock::now();
  impl.Lookup(this, in, samples->GetWidth(), samples->GetHeight(), anyCaster, vis);
  this->LookupTimeMs = ElapsedMs(lookupStart);
  visibility->Modified();
  this->LastTimeMs = ElapsedMs(start);
  return 1;
}

//------------------------------------------------------------------------------
void vtkPenumbraSoftShadowMapShadows::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Elements: " << this->Elements << "\n";
  os << indent << "Fit: " << this->Fit << "\n";
  os << indent << "Block: " << this->Block << "\n";
  os << indent << "NumberOfLineSamples: " << this->NumberOfLineSamples << "\n";
  os << indent << "GridSamples: " << this->GridSamples << "\n";
  os << indent << "Resolution: " << this->Resolution << "\n";
  os << indent << "Threshold: " << this->Threshold << "\n";
  os << indent << "Bias: " << this->Bias << "\n";
  os << indent << "SlopeBias: " << this->SlopeBias << "\n";
  os << indent << "NumberOfMaps: " << this->NumberOfMaps << "\n";
  os << indent << "NumberOfSkins: " << this->NumberOfSkins << "\n";
}

//------------------------------------------------------------------------------
const char* vtkPenumbraSoftShadowMapShadows::GetTechniqueNameFor(vtkLight* light)
{
  return vtkPenumbraAreaLight::SafeDownCast(light) ? "soft-shadowmap" : "shadowmap";
}

//------------------------------------------------------------------------------
void vtkPenumbraSoftShadowMapShadows::GetStatistics(vtkLight* light, vtkPenumbraStatistics* stats)
{
  this->Superclass::GetStatistics(light, stats);
  stats->Set("builds", this->NumberOfBuilds);
  stats->Set("maps", this->NumberOfMaps);
  stats->Set("skins", static_cast<double>(this->NumberOfSkins));
  stats->Set("map_ms", this->MapTimeMs);
  stats->Set("skin_ms", this->SkinTimeMs);
  stats->Set("lookup_ms", this->LookupTimeMs);
}
