/**
 * @file   vtkPenumbraShadowVolumeInternals.h
 * @brief  The state of a vtkPenumbraShadowVolumeShadows shared by its files: the phases of a
 *         call (vtkPenumbraShadowVolumeShadows.cxx), the caster connectivity
 *         (vtkPenumbraShadowVolumeConnectivity.cxx), the volumes and their cache
 *         (vtkPenumbraShadowVolumeBuilder.cxx), the outline for the edge resolve
 *         (vtkPenumbraShadowVolumeOutline.cxx) and the GL counting in the stencil
 *         (vtkPenumbraShadowVolumeStencil.cxx). Private to the module.
 */

#ifndef vtkPenumbraShadowVolumeInternals_h
#define vtkPenumbraShadowVolumeInternals_h

#include "vtkPenumbraShadowVolumeShadows.h"

#include "vtkIdTypeArray.h"
#include "vtkNew.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraLightViews.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"
#include "vtkWeakPointer.h"
#include "vtk_glew.h"

// GCC 12 reports a false -Wmaybe-uninitialized inside OpenMesh's property push_back.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <OpenMesh/Core/Mesh/TriConnectivity.hh>
#include <OpenMesh/Core/System/omstream.hh>
#pragma GCC diagnostic pop

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

class vtkCamera;
class vtkFloatArray;
class vtkLight;
class vtkOpenGLState;
class vtkPenumbraSceneGeometry;
class vtkPenumbraViewSamples;
class vtkRenderer;
class vtkShaderProgram;

namespace penumbra_shadow_volume
{
using penumbra::Clock;
using penumbra::ElapsedMs;
using Vec3 = glm::dvec3;

enum : unsigned char
{
  Decided = 0,
  Pending = 1
};

// Caster connectivity (OpenMesh): welded vertices, closed components for
// silhouette volumes, everything else as loose triangles for per-triangle volumes.
struct Connectivity
{
  struct Component
  {
    // Closed (no boundary edge, non-zero volume): silhouette volumes of the light-facing
    // faces suffice. Open: both face sets are needed (see the volume builder).
    bool Closed = false;
    // Faces as welded vertex triples; closed components are already turned so that their
    // winding is outward (components of negative volume are reversed once here).
    std::vector<std::array<int, 3>> Faces;
    // Per face, the face across each of its edges (t[k] -> t[k + 1]), an index into Faces;
    // -1 on a boundary edge.
    std::vector<std::array<int, 3>> Neighbors;
    // Per face, GL_TRIANGLES_ADJACENCY order: v0, opposite of (v0, v1), v1, opposite of
    // (v1, v2), v2, opposite of (v2, v0) (the GPU silhouette path).
    std::vector<std::array<int, 6>> Adjacency;
    double Bounds[6] = { VTK_DOUBLE_MAX, -VTK_DOUBLE_MAX, VTK_DOUBLE_MAX, -VTK_DOUBLE_MAX,
      VTK_DOUBLE_MAX, -VTK_DOUBLE_MAX };

    // Every edge once, as { v0, v1, F0, F1 }: v0 -> v1 in face F0's winding, v1 -> v0 in
    // F1's, F1 -1 on a boundary edge.
    template <class EdgeFn>
    void ForEachEdge(EdgeFn visit) const
    {
      for (size_t f = 0; f < this->Faces.size(); ++f)
      {
        for (size_t k = 0; k < 3; ++k)
        {
          const int g = this->Neighbors[f][k];
          if (g < 0 || static_cast<int>(f) < g)
          {
            visit(std::array<int, 4>{
              this->Faces[f][k], this->Faces[f][(k + 1) % 3], static_cast<int>(f), g });
          }
        }
      }
    }
  };
  std::vector<Vec3> Points;
  std::vector<Component> Components;
  std::vector<std::array<int, 3>> Loose;
  vtkIdType Casters = 0;
  vtkIdType Complex = 0;
  vtkIdType BoundaryEdges = 0;

  // Connectivity alone: no points (they are in Points).
  using OMesh = OpenMesh::TriConnectivity;
  static constexpr int Refused = -2;

  // `adjacency`: also the closed components' Adjacency (the GPU silhouette path alone uses
  // it; 24 bytes a face).
  void Build(vtkPenumbraSceneGeometry* geometry, bool silhouettes, bool adjacency);
  std::vector<std::array<int, 3>> WeldCasters(
    vtkPenumbraSceneGeometry* geometry, std::vector<std::uint32_t>& source);
  std::vector<std::array<int, 3>> Across(
    const std::vector<std::array<int, 3>>& tris, size_t points);
  void BuildComponents(const std::vector<std::array<int, 3>>& tris,
    const std::vector<std::array<int, 3>>& across, bool adjacency);
  void FinishComponent(Component& c, bool closed, bool adjacency) const;
  void Orient(Component& c) const;
  static void AddAdjacency(Component& c);
};

// The light as the volume builder needs it: a direction toward a directional light or a
// rebased position.
struct VolumeLight
{
  bool Directional = true;
  Vec3 Direction = { 0, 0, 1 };
  Vec3 Position = { 0, 0, 0 };
  double Extrusion = 1.0; // directional: prism length beyond everything

  // Everything above, as a cache key of what is made for the light.
  std::vector<double> Key() const
  {
    return { this->Directional ? 1.0 : 0.0, this->Direction[0], this->Direction[1],
      this->Direction[2], this->Position[0], this->Position[1], this->Position[2],
      this->Extrusion };
  }

  // Outward facing test value of an oriented triangle: > 0 means it faces the light.
  double Facing(const Vec3& a, const Vec3& b, const Vec3& c) const
  {
    const Vec3 n = glm::cross(b - a, c - a);
    return this->Directional ? glm::dot(n, this->Direction) : glm::dot(n, this->Position - a);
  }
  // Direction of extrusion at v (away from the light), not normalized.
  Vec3 Away(const Vec3& v) const
  {
    return this->Directional ? -this->Direction : (v - this->Position);
  }
};

// Volume vertices as drawn (xyzw floats), each with its point's identity: mesh point i is
// NearId(i), its extruded copy FarId(i). Equal identities are equal floats, so the outline
// (VolumeOutline) takes its topology from the identities without welding floats.
struct VolumeStream
{
  std::vector<float> V;
  std::vector<int> Id;

  static int NearId(int i) { return 2 * i; }
  static int FarId(int i) { return 2 * i + 1; }
  void Put(double x, double y, double z, double w, int id)
  {
    this->V.insert(this->V.end(),
      { static_cast<float>(x), static_cast<float>(y), static_cast<float>(z),
        static_cast<float>(w) });
    this->Id.push_back(id);
  }
  void Append(const VolumeStream& o)
  {
    this->V.insert(this->V.end(), o.V.begin(), o.V.end());
    this->Id.insert(this->Id.end(), o.Id.begin(), o.Id.end());
  }
  // Vertices (4 floats each).
  size_t Size() const { return this->V.size() / 4; }
  // Frees the identities once the outline has been built from them.
  void ForgetIds() { std::vector<int>().swap(this->Id); }
};

// Where each view sample is counted. The stencil counts along the camera's pixel-centre rays
// and a pixel holds one depth, so a sample is counted at the pixel whose centre ray passes
// through it, found by projecting the sample with the camera, never from its index: a shadow
// pass may hand over several surfaces per pixel (opaque rows, then the nearest translucent
// surface's rows, stacked into one array), and any other arrangement works the same way.
// Samples that meet an occupied pixel go to the next layer of the counting image; each layer
// is one full view, drawn with its own viewport (Brabec 2003, ch. 8: the scene depth once,
// then the volumes; here once per layer). Samples off every pixel centre, or beyond
// MaxLayers, cannot be counted and are traced.
struct SampleLayout
{
  static constexpr int MaxLayers = 4;
  // Largest distance, in pixels, between a sample's projection and its pixel centre: the
  // G-buffer's samples lie on the centres up to float rounding (far below this), while the
  // rasterizer's own snapping is 1/256 pixel (see the edge resolve).
  static constexpr double CentreTolerance = 1.0 / 64.0;

  int Width = 0; // one layer (the view), in pixels
  int Height = 0;
  int Layers = 0;
  std::vector<vtkIdType> Pixel;    // per sample: its pixel in the Width x (Height Layers)
                                   // counting image, -1: not counted
  std::vector<vtkIdType> SampleAt; // per pixel of the counting image: its sample, -1: none
  std::vector<float> DepthStencil; // per pixel: float depth, uint32 (stencil in the low byte)
  vtkIdType Unplaced = 0;          // samples that see a surface but are not counted

  void Place(const penumbra_light_views::FrameInputs& in, const double projection[4][4], int width,
    int height);
  void ComputeDepths(const penumbra_light_views::FrameInputs& in, const double rows[4][4],
    const double unproject[4][4], const double origin[3], double scale);
};

// The volumes' outline as the camera sees it: the volume edges near which the stencil count
// can be wrong. The rasterizer decides a triangle's coverage of a pixel centre on a snapped
// sub-pixel grid (1/256 pixel on llvmpipe), so a centre closer than that to a projected
// triangle edge may be counted on the wrong side of it. Where an edge is shared by two volume
// faces that both face the camera (or both face away) with opposite windings, the two
// triangles lie on either side of the same snapped edge and the rasterizer covers every
// centre with exactly one of them: the count is the same as the exact one. Every other edge
// (a front-facing and a back-facing face meeting: the volume's silhouette from the eye,
// including cap edges; faces seen edge-on; unpaired edges) can change the count across it.
// A shadow narrower than a pixel lies entirely within snapping distance of such edges, so it
// cannot be trusted to the neighbour test (Brabec 2003, ch. 3 and 9 for the silhouette
// notions; here they are applied to the volume itself, from the eye).
//
// Most volume edges of a closed mesh join the caps of two faces of the same set (a cap's
// interior): those are judged from the connectivity by the two caps' screen sides
// (MarkOutline), with nothing kept per edge. The rest (caps on the set's border, sides,
// per-triangle volumes, the geometry stage's volumes) are kept as triangles with their edges
// and incidences (Build, Mark), a share of the volumes the size of their silhouettes.
struct VolumeOutline
{
  // Pixel centres closer than this (pixels, in x and in y) to an outline edge are traced. It
  // covers the rasterizer's snapping (1/512 pixel of rounding) and the difference between
  // the GPU's float32 vertex transform and the double one here with a wide margin.
  static constexpr double Reach = 1.0 / 32.0;

  std::vector<std::array<double, 4>> Points; // volume vertices, rebased, homogeneous
  std::vector<std::array<int, 3>> Faces;     // volume triangles as drawn (their winding)
  std::vector<std::array<int, 2>> Edges;     // undirected, first < second
  std::vector<int> EdgeStart;                // edge e's incidences: [EdgeStart[e], [e + 1])
  std::vector<int> Incidences;               // 2 face + 1 when the face runs first -> second
  std::vector<std::array<int, 2>> Forced;    // segments always on the outline
  // Edges of the kept triangles that MarkOutline judges (by their points' identities,
  // VolumeStream numbers): skipped here, as each edge is judged once with all its faces.
  std::vector<std::uint64_t> Skip; // sorted
  // Same-kind edges of the explicit triangles (per-triangle volumes, sides): a component edge
  // among them is judged here with all its faces, never as a cap interior's. Sorted.
  std::vector<std::uint64_t> Shared;
  std::vector<int> PointId; // per point: its identity (VolumeStream numbering)
  // Per frame.
  std::vector<std::array<double, 3>> Projected; // clip x, y, w of each point
  std::vector<signed char> FaceSide;            // sign of the homogeneous screen area

  void Clear() { *this = VolumeOutline(); }

  void Build(const VolumeStream& triangles, const VolumeStream& forced, size_t meshPoints);
  void Mark(
    const double projection[4][4], int width, int height, std::vector<unsigned char>& pixels);
  static void MarkSegment(const std::array<double, 3>& p, const std::array<double, 3>& q, int width,
    int height, std::vector<unsigned char>& pixels);
  // The undirected pair of two point identities, as Skip holds it.
  static std::uint64_t Pair(int a, int b)
  {
    const std::uint32_t lo = static_cast<std::uint32_t>(std::min(a, b));
    const std::uint32_t hi = static_cast<std::uint32_t>(std::max(a, b));
    return (static_cast<std::uint64_t>(lo) << 32) | hi;
  }
};
}

struct vtkPenumbraShadowVolumeShadows::Internals
{
  vtkWeakPointer<vtkOpenGLRenderWindow> Window;
  GLuint Framebuffer = 0;
  GLuint DepthStencil = 0;
  GLuint MaskTexture = 0; // RGBA8: one light per channel, 0 = shadow (Brabec 2003, ch. 8)
  GLuint VertexArray = 0;
  GLuint Query = 0;
  GLuint PointArray = 0;  // GPU silhouettes: VAO of the welded points
  GLuint PointBuffer = 0; // the welded points (xyz float), once per connectivity: the caps'
                          // near corners of every set, and the GPU silhouettes' input
  bool PointsUploaded = false;
  int Width = 0;
  int Height = 0;

  // Connectivity cache.
  penumbra_shadow_volume::Connectivity Mesh;
  penumbra::CastersStamp MeshBuilt;
  double Origin[3] = { 0, 0, 0 }; // the geometry's Origin the mesh was built in
  bool BuiltWithSilhouettes = true;
  bool BuiltWithAdjacency = false;

  // Volume cache, one entry per light (several lights render every frame): rebuilt when the
  // light, the connectivity, the sample box (with culling) or the options change. Each set
  // keeps its own GL buffers, so lights that do not move upload nothing.
  //
  // A closed component's caps are not kept as vertices: per face its set (1 light-facing, -1
  // back-facing turned toward the light, 0 none), and on the GPU the caps as one index triple
  // per face with a set, drawn twice: into the mesh points (PointBuffer, shared by every set;
  // VolumeStream's identities 2i) as the light caps, and into the set's extruded copies
  // (FarBuffer, xyz, their w the shader's pointW; identities 2i + 1) with the front face
  // swapped, i.e. the other winding, as the dark caps: the same vertices, in the same float32
  // values, as the explicit triangles they replace. The rest (sides, per-triangle volumes)
  // stays explicit.
  struct VolumeSet
  {
    std::vector<double> Key;
    double Box[6] = { 0, 0, 0, 0, 0, 0 };      // with Cull: the box it was culled to (CullMargin)
    std::uint64_t Stamp = 0;                   // last use: the least recently used set is evicted
    penumbra_shadow_volume::VolumeLight Light; // what the extruded copies are made for
    double FarW = 0.0; // positional lights: w of the extruded copies (PositionalFarW)
    std::vector<std::vector<signed char>> Sets;     // per component and face (empty: GPU drawn)
    vtkIdType CapFaces = 0;                         // faces with a set: two caps each
    penumbra_shadow_volume::VolumeStream LightCaps; // per-triangle volumes' light caps
    penumbra_shadow_volume::VolumeStream Rest;      // their dark caps and sides, components' sides
    std::vector<GLuint> AdjacencyIndices;           // GPU silhouettes
    GLsizei AdjacencyCount = 0;
    vtkIdType SilhouetteEdges = 0;
    vtkIdType Culled = 0;
    GLuint FarBuffer = 0;       // the extruded copies (xyz), uploaded on first use
    GLuint CapBuffer = 0;       // the caps' indices, light-cap winding
    GLuint StreamBuffer = 0;    // LightCaps then Rest, xyzw
    GLuint AdjacencyBuffer = 0; // adjacency indices, uploaded on first use
    // With the edge resolve: the volumes' edges, for the outline from the camera.
    penumbra_shadow_volume::VolumeOutline Outline;

    // Near (mesh point i) or far (its extrusion) copy of volume point `id` (VolumeStream's
    // numbering), as the GPU draws it: VolumeBuilder's Near and Far, rounded as
    // VolumeStream::Put rounds them.
    void TablePoint(const penumbra_shadow_volume::Connectivity& mesh, int id, float xyzw[4]) const
    {
      const penumbra_shadow_volume::Vec3& v = mesh.Points[static_cast<size_t>(id / 2)];
      const penumbra_shadow_volume::VolumeLight& vl = this->Light;
      if (id % 2 == 0)
      {
        NearPoint(v, xyzw);
        return;
      }
      for (int c = 0; c < 3; ++c)
      {
        xyzw[c] =
          static_cast<float>(vl.Directional ? v[c] - vl.Extrusion * vl.Direction[c]
                                            : v[c] - vl.Position[c] + this->FarW * vl.Position[c]);
      }
      xyzw[3] = this->FarPointW();
    }
    static void NearPoint(const penumbra_shadow_volume::Vec3& v, float xyzw[4])
    {
      xyzw[0] = static_cast<float>(v[0]);
      xyzw[1] = static_cast<float>(v[1]);
      xyzw[2] = static_cast<float>(v[2]);
      xyzw[3] = 1.0f;
    }
    // The w of every extruded copy.
    float FarPointW() const
    {
      return this->Light.Directional ? 1.0f : static_cast<float>(this->FarW);
    }
    // Face f of component c as its caps are drawn: corners turned toward the light.
    static std::array<int, 3> CapCorners(
      const penumbra_shadow_volume::Connectivity::Component& c, size_t f, signed char set);
    GLsizei StreamVertices() const
    {
      return static_cast<GLsizei>(this->LightCaps.Size() + this->Rest.Size());
    }
  };
  // More sets than lights per mask: a group never evicts a set it is using.
  static constexpr size_t MaxVolumeSets = 8;
  std::vector<std::unique_ptr<VolumeSet>> Volumes;
  std::uint64_t Clock = 0;
  std::vector<GLuint> Garbage; // buffers of evicted sets, deleted when the context is current

  // Per light of the group, the edge resolve's last subset of casters (LimitBlockers) and
  // what it was made from: the light, the casters and the samples' frame (Key), the traced
  // samples and their positions.
  struct BlockerCache
  {
    std::vector<double> Key;
    std::vector<vtkIdType> Samples;
    std::vector<float> Positions;
    vtkSmartPointer<vtkIdTypeArray> Subset;
  };
  std::vector<BlockerCache> Blockers;

  // Per-frame camera data shared by every light (see ComputeGroup).
  std::vector<double> DepthKey;
  double Rows[4][4] = {};
  double Projection[4][4] = {};             // world -> clip as VTK draws it, rebased (x, y, w rows)
  std::vector<unsigned char> OutlinePixels; // one light's outline (VolumeOutline::Mark)
  bool DepthUploaded = false;
  penumbra_shadow_volume::SampleLayout Layout; // where each sample is counted, and the depths
  std::vector<unsigned char> MaskPixels;
  vtkNew<vtkUnsignedCharArray> Mask;

  static void BuildVolumes(VolumeSet& build, const penumbra_shadow_volume::Connectivity& mesh,
    const penumbra_shadow_volume::VolumeLight& vl, const double* box, const double bounds[6],
    bool gpu, bool outline);
  static void BuildOutline(VolumeSet& build, const penumbra_shadow_volume::Connectivity& mesh,
    const penumbra_shadow_volume::VolumeStream& gpuVolumes,
    const penumbra_shadow_volume::VolumeStream& gpuUncertain);
  void MarkOutline(VolumeSet& vs, int width, int height);
  void Evict(size_t i);
  void ClearVolumes();
  void Release(vtkWindow* window);
  void CollectGarbage();
  bool Allocate(int w, int h, vtkOpenGLState* ostate);

  // ---- One ComputeGroup call, in named phases (ComputeGroup runs them in order).
  // One light of the group.
  struct Job
  {
    vtkLight* Light = nullptr;
    vtkFloatArray* Visibility = nullptr;
    float* Vis = nullptr;
    penumbra_light_views::FrameInputs In;
    std::vector<unsigned char> State;
    penumbra_shadow_volume::VolumeLight VL;
    VolumeSet* Volumes = nullptr; // null: nothing to count (no pending sample)
    bool ZPass = false;
    int Channel = -1; // its channel in the mask
  };

  // What the phases of one call share.
  struct Group
  {
    vtkRenderer* Renderer = nullptr;
    vtkPenumbraSceneGeometry* Geometry = nullptr;
    vtkPenumbraViewSamples* Samples = nullptr;
    std::vector<Job> Jobs;
    // What depends on the samples, the geometry and the window only (ReadShared): the same
    // for every job, so the first job's.
    const penumbra_light_views::FrameInputs* In = nullptr;
    vtkOpenGLRenderWindow* Window = nullptr;
    vtkIdType N = 0;
    int Width = 0;
    int Height = 0;
    vtkCamera* Camera = nullptr;
    double Scale = 1.0; // scene scale (UpdateConnectivity)
    double RebasedBounds[6] = { 0, 0, 0, 0, 0, 0 };
    int Counted = 0; // lights with samples to count, one mask channel each
    bool Parallel = false;
    penumbra::Clock::time_point StencilStart; // sample depths and counting (StencilTimeMs)
    vtkShaderProgram* Program = nullptr;
    vtkShaderProgram* GSProgram = nullptr; // null: no GPU silhouettes in this group
    vtkShaderProgram* MaskProgram = nullptr;
  };

  static void ReadJobs(vtkPenumbraShadowVolumeShadows& self, Group& g, vtkLight* const* lights,
    vtkFloatArray* const* visibilities, int count);
  static const char* ReadShared(Group& g);
  void UpdateConnectivity(vtkPenumbraShadowVolumeShadows& self, Group& g);
  void PrepareLights(vtkPenumbraShadowVolumeShadows& self, Group& g);
  bool PrepareLight(vtkPenumbraShadowVolumeShadows& self, const Group& g, Job& job);
  static void PendingBox(const penumbra_light_views::FrameInputs& in,
    const std::vector<unsigned char>& state, double scale, double box[6]);

  // A set of volumes is culled to the pending box grown by a fifth of its largest side
  // (penumbra_light_views::KeptBox): culling keeps every volume that reaches that box, so the
  // set serves every later pending box inside it with the same counts, and outlives the
  // small camera moves of an interaction instead of being rebuilt every frame.
  static constexpr double CullMargin = 0.2;

  VolumeSet* FindVolumes(vtkPenumbraShadowVolumeShadows& self, const Group& g,
    const penumbra_shadow_volume::VolumeLight& vl, const double box[6]);
  void ComputeSampleDepths(vtkPenumbraShadowVolumeShadows& self, Group& g);
  void CameraRows(vtkCamera* camera, double aspect, bool parallel,
    const penumbra_light_views::FrameInputs& in, double unproject[4][4], double projection[4][4]);
  void ChooseMethods(vtkPenumbraShadowVolumeShadows& self, Group& g);
  const char* ReadyGL(Group& g);
  static vtkShaderProgram* ReadyProgram(
    vtkOpenGLRenderWindow* win, const char* vs, const char* fs, const char* gs);
  static bool HasDepthClamp();
  bool CountInStencil(vtkPenumbraShadowVolumeShadows& self, const Group& g);
  void CountLayers(vtkPenumbraShadowVolumeShadows& self, const Group& g, vtkOpenGLState* ostate);
  void UploadPoints();
  void CountLayer(vtkPenumbraShadowVolumeShadows& self, const Group& g, vtkOpenGLState* ostate,
    int layer, float matrix[16]);
  void CountLight(vtkPenumbraShadowVolumeShadows& self, const Group& g, vtkOpenGLState* ostate,
    const Job& job, float matrix[16]);
  void BindVolumeBuffers(const Group& g, VolumeSet& vs);
  void UploadCaps(VolumeSet& vs);
  static void BindBuffer(GLenum target, GLuint& buffer, GLsizeiptr bytes, const void* data);
  void DrawVolumes(const Group& g, const VolumeSet& vs,
    const penumbra_shadow_volume::VolumeLight& vl, float matrix[16], float capScale);
  int FinishLights(vtkPenumbraShadowVolumeShadows& self, const Group& g);
  void ApplyMask(const Group& g, const Job& job);
  bool TraceUncertain(vtkPenumbraShadowVolumeShadows& self, const Group& g, const Job& job);
  void LimitBlockers(vtkPenumbraShadowVolumeShadows& self, const Group& g, const Job& job,
    const unsigned char* traced);
};

#endif
// VTK-HeaderTest-Exclude: vtkPenumbraShadowVolumeInternals.h
