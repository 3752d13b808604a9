// The exact family's techniques as the registry lists them (raytraced, adaptive-soft,
// conservative, llsm, llsm-hybrid, volumes): each one's option table and factory, beside the
// classes they configure.
#include "vtkPenumbraExactTechniques.h"

#include "vtkPenumbraConservativeShadows.h"
#include "vtkPenumbraLinkedListShadows.h"
#include "vtkPenumbraRayTracedShadows.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraShadowVolumeShadows.h"

namespace
{
using namespace penumbra_options;

const OptionTable RayTracedOptions = { SamplesOption() };

const OptionTable AdaptiveSoftOptions = { SamplesOption(),
  { "block", OptionType::Integer, 8, 2, 16, {}, "pixels",
    "top block size: the exact rays are traced at the corners and centre of blocks this "
    "wide; a block whose corners predict its centre is interpolated, any other is split in "
    "four, down to 2 pixels" },
  { "tolerance", OptionType::Number, 0.05, 0.0, 1.0, {}, "visibility",
    "largest difference between a block centre's traced visibility and its bilinear "
    "prediction for which the block is interpolated" } };

// raytraced; adaptive-soft is the same tracer with its adaptive block set.
vtkSmartPointer<vtkPenumbraShadowTechnique> CreateRayTraced(const Options& opts, bool adaptive)
{
  auto technique = vtkSmartPointer<vtkPenumbraRayTracedShadows>::New();
  technique->SetSamplesPerAxis(opts.Integer("samples"));
  if (adaptive)
  {
    technique->SetAdaptiveBlock(opts.Integer("block"));
    technique->SetAdaptiveTolerance(opts.Number("tolerance"));
  }
  return technique;
}

const OptionTable ConservativeOptions = {
  { "resolution", OptionType::Integer, 1024, 64, 8192, {}, "texels",
    "conservative shadow map texels per side (per cube face for point lights)" },
  { "layers", OptionType::Integer, 2, 2, 4, {}, "",
    "depth-peeled map layers; more layers let more samples look past their own and "
    "neighbouring triangles, but cost more than the rays they save on llvmpipe" },
  { "map", OptionType::Choice, "cpu", 0, 0, { "cpu", "gpu" }, "",
    "who builds the map: \"cpu\", exact conservative rasterization in double precision with "
    "vtkSMPTools (the faster on llvmpipe), or \"gpu\", a geometry-shader program with "
    "one draw per layer, read back; both are exact" },
};

vtkSmartPointer<vtkPenumbraShadowTechnique> CreateConservative(const Options& opts)
{
  auto technique = vtkSmartPointer<vtkPenumbraConservativeShadows>::New();
  technique->SetResolution(opts.Integer("resolution"));
  technique->SetLayers(opts.Integer("layers"));
  technique->SetMapBuilder(opts.Choice("map") == 1 ? vtkPenumbraConservativeShadows::MAP_GPU
                                                   : vtkPenumbraConservativeShadows::MAP_CPU);
  return technique;
}

const OptionTable LinkedListOptions = {
  { "resolution", OptionType::Integer, 1024, 1, 4096, {}, "texels",
    "list-grid texels per side (per cube face for point lights); only speed depends on it: "
    "fewer texels give longer lists, 1 tests every caster against every sample" },
  { "capacity", OptionType::Integer, 0, 0, 2147483647, {}, "samples",
    "node-pool size: at most this many samples are listed per pass, the others in further "
    "passes (none is dropped); 0: one node per sample, one pass" },
  { "lists", OptionType::Choice, "cpu", 0, 0, { "cpu", "gpu" }, "",
    "who builds the per-texel lists: \"cpu\", a sort by texel (the faster on Mesa "
    "llvmpipe), or \"gpu\", Ferko 2014's construction in a GL 4.3 compute shader (node pool, "
    "atomic counter, atomic head exchange; an overflowing pool lists the rest in another "
    "pass); the same lists and visibility, and the CPU builds them (with an error) where "
    "OpenGL 4.3 is missing" },
};

// llsm-hybrid: llsm's options and its classifier's.
OptionTable LinkedListHybridTable()
{
  OptionTable table = LinkedListOptions;
  table.push_back({ "classify_resolution", OptionType::Integer, 1024, 64, 8192, {}, "texels",
    "texels per side of the conservative shadow map that decides the easy samples" });
  table.push_back({ "classify_layers", OptionType::Integer, 3, 2, 4, {}, "",
    "depth-peeled layers of that map: each decides more samples without the lists (3 "
    "against 2: 0.6 % instead of 5.8 % of the city's samples listed, 4.6 % instead of 7.7 % "
    "of the isosurface's) at one more layer to build when the light or the view moves; 3 "
    "was the fastest with a still and with a moving light" });
  return table;
}
const OptionTable LinkedListHybridOptions = LinkedListHybridTable();

vtkSmartPointer<vtkPenumbraShadowTechnique> CreateLinkedList(const Options& opts, bool hybrid)
{
  auto technique = vtkSmartPointer<vtkPenumbraLinkedListShadows>::New();
  technique->SetResolution(opts.Integer("resolution"));
  technique->SetListCapacity(opts.Integer("capacity"));
  technique->SetListBuilder(opts.Choice("lists") == 1 ? vtkPenumbraLinkedListShadows::LISTS_GPU
                                                      : vtkPenumbraLinkedListShadows::LISTS_CPU);
  technique->SetHybrid(hybrid);
  if (hybrid)
  {
    technique->GetClassifier()->SetResolution(opts.Integer("classify_resolution"));
    technique->GetClassifier()->SetLayers(opts.Integer("classify_layers"));
  }
  return technique;
}

const OptionTable VolumesOptions = {
  { "silhouettes", OptionType::Choice, "cpu", 0, 0, { "cpu", "gpu", "none" }, "",
    "\"cpu\": silhouette edges from OpenMesh half-edges, in double; \"gpu\": a geometry shader "
    "with triangle adjacency finds and extrudes them (Brabec 2003, ch. 9); \"none\": one volume "
    "per triangle for every caster, the brute-force baseline" },
  { "method", OptionType::Choice, "auto", 0, 0, { "auto", "zfail", "zpass" }, "",
    "\"auto\": z-pass when the camera provably lies outside every volume, else z-fail; "
    "\"zfail\": always (caps and depth clamp make it correct with the camera inside a volume); "
    "\"zpass\": always, wrong where the camera is inside a volume (for comparison only)" },
  { "cull", OptionType::Boolean, true, 0, 0, {}, "",
    "skip casters whose volumes cannot reach the box of the light-facing samples" },
  { "cap_offset", OptionType::Number, 1.0 / 131072.0, 0.0, 1e-3, {}, "fraction of eye depth",
    "how far light caps are pushed back (default 2^-17), so that a sample never counts its own "
    "caster surface" },
  { "resolve", OptionType::Boolean, true, 0, 0, {}, "",
    "ray trace the samples next to a change of the stencil result, next to background or "
    "facing-away samples, and those the light grazes (cosine below 1e-3); false gives the pure "
    "stencil answer" },
  { "measure_fill", OptionType::Boolean, false, 0, 0, {}, "",
    "draw the volumes once more without depth test to count their fragments (the bench's fill "
    "column)" },
  { "lights_per_mask", OptionType::Integer, 4, 1, 4, {}, "lights",
    "lights counted into one RGBA mask before it is read back (Brabec 2003, ch. 8); only speed "
    "depends on it" },
  { "subset_above", OptionType::Integer, 1 << 20, 0, 2147483647.0, {}, "casters",
    "casters above which the edge resolve traces through an Embree scene of only the casters "
    "that can block its samples (a light-space grid of them; the same answers) and compacts "
    "it: less memory than a BVH of every caster, for a pass over the casters whenever the "
    "traced samples change; 0: always" },
};

vtkSmartPointer<vtkPenumbraShadowTechnique> CreateVolumes(const Options& opts)
{
  const int silhouettes = opts.Choice("silhouettes");
  const int method = opts.Choice("method");
  auto technique = vtkSmartPointer<vtkPenumbraShadowVolumeShadows>::New();
  technique->SetSilhouettes(silhouettes != 2);
  technique->SetGPUSilhouettes(silhouettes == 1);
  technique->SetMethod(method == 1 ? vtkPenumbraShadowVolumeShadows::METHOD_ZFAIL
      : method == 2                ? vtkPenumbraShadowVolumeShadows::METHOD_ZPASS
                                   : vtkPenumbraShadowVolumeShadows::METHOD_AUTO);
  technique->SetCull(opts.Boolean("cull"));
  technique->SetCapOffset(opts.Number("cap_offset"));
  technique->SetResolve(opts.Boolean("resolve"));
  technique->SetMeasureFill(opts.Boolean("measure_fill"));
  technique->SetLightsPerMask(opts.Integer("lights_per_mask"));
  technique->GetReference()->SetCompactAbove(opts.Integer("subset_above"));
  return technique;
}

}

// The descriptions cite the papers by short name:
// - Hertel et al. 2009: Hertel, Hormann, Westermann, "A Hybrid GPU Rendering Pipeline for
//   Alias-Free Hard Shadows", Eurographics 2009 Areas Papers;
// - Brabec 2003: Brabec, "Shadow Techniques for Interactive and Real-Time Applications", PhD
//   thesis, 2003;
// - Ferko 2014: Ferko, linked-list shadow maps (LLSM), the irregular z-buffer of Johnson et al.
//   2005 built with per-texel linked lists, in the same thesis.
const penumbra_options::TechniqueList& penumbra_exact_shadows::Techniques()
{
  static const TechniqueList techniques = {
    { "raytraced",
      "exact shadows from every light type, ray traced on the CPU (Embree) for every view sample "
      "and light sample",
      RayTracedOptions, [](const Options& opts) { return CreateRayTraced(opts, false); } },
    { "adaptive-soft",
      "approximate soft shadows for area and linear lights: the exact rays of raytraced at a "
      "lattice of view samples, blocks whose corners predict their centre interpolated, the "
      "others split down to 2 pixels (the adaptive sampling of Brabec 2003, ch. 11.3); hard "
      "lights exact",
      AdaptiveSoftOptions, [](const Options& opts) { return CreateRayTraced(opts, true); } },
    { "conservative",
      "exact hard shadows from point, spot and directional lights: a conservative shadow map "
      "classifies the samples as lit, shadowed or uncertain, CPU rays resolve the uncertain ones "
      "(Hertel et al. 2009)",
      ConservativeOptions, CreateConservative },
    { "llsm",
      "exact hard shadows without rays where they can be decided: linked-list shadow maps "
      "(Ferko 2014), per light-view texel a list of the view samples, every caster rasterized "
      "conservatively and tested exactly against the samples of the texels it covers; CPU rays "
      "only for undecidable ones; point, spot and directional lights",
      LinkedListOptions, [](const Options& opts) { return CreateLinkedList(opts, false); } },
    { "llsm-hybrid",
      "llsm for the hard samples only: a conservative shadow map (Hertel et al. 2009) decides "
      "the easy ones, the lists the rest (the hybrid LLSM of Ferko's thesis, with an exact "
      "classifier)",
      LinkedListHybridOptions, [](const Options& opts) { return CreateLinkedList(opts, true); } },
    { "volumes",
      "exact hard shadows with stencil shadow volumes (Brabec 2003, ch. 3, 8, 9): OpenMesh "
      "silhouettes for closed meshes, per-triangle volumes otherwise, z-fail with caps and "
      "depth clamp, four lights per RGBA mask; point, spot and directional lights",
      VolumesOptions, CreateVolumes },
  };
  return techniques;
}
