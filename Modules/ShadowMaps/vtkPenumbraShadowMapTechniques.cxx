// The shadow-map family's techniques as the registry lists them (shadowmap, resm, rmsm, pcss,
// single-sample-soft, soft-shadowmap): each one's option table and factory, beside the classes
// they configure.
#include "vtkPenumbraShadowMapTechniques.h"

#include "vtkPenumbraResolutionMatchedShadows.h"
#include "vtkPenumbraShadowMapShadows.h"
#include "vtkPenumbraSoftShadowMapShadows.h"

namespace
{
using namespace penumbra_options;

const OptionTable ShadowMapOptions = {
  { "resolution", OptionType::Integer, 2048, 64, 8192, {}, "texels",
    "texels per side (per cube face or paraboloid hemisphere for point lights)" },
  { "filter", OptionType::Choice, "none", 0, 0, { "none", "pcf", "bilinear" }, "",
    "\"none\": the nearest texel, 0/1 like a hardware compare; \"pcf\": percentage-closer "
    "filtering, the mean of the compared taps (fractional visibility at shadow edges); "
    "\"bilinear\": Fast PCF (Brabec 2003, ch. 5), the 2 x 2 adjacent compared texels weighted "
    "bilinearly (a one-texel ramp at edges, four taps)" },
  { "pcf_kernel", OptionType::Integer, 3, 3, 9, { 3, 5, 7, 9 }, "texels",
    "odd kernel width of \"pcf\"" },
  { "bias", OptionType::Number, 1e-4, 0.0, 0.1, {}, "fraction of the depth range",
    "constant depth bias as a fraction of the light view's depth range (orthographic: the "
    "fitted receiver depth span; perspective/paraboloid: the farthest receiver's distance)" },
  { "slope_bias", OptionType::Number, 1.0, 0.0, 16.0, {}, "texel footprints",
    "slope-scaled bias in texel footprints (times 1 + the filter's reach: PCF radius, 1 for "
    "bilinear; the slope's tangent is capped "
    "at 1000)" },
  { "depth", OptionType::Choice, "linear", 0, 0, { "linear", "midpoint" }, "",
    "\"linear\": nearest surface; \"midpoint\": Woo's midpoint of the first two surfaces, one "
    "more depth-peeled pass per view" },
  { "point", OptionType::Choice, "cube", 0, 0, { "cube", "paraboloid" }, "",
    "point lights: \"cube\", six 90-degree faces (only those holding receivers are rendered), "
    "or \"paraboloid\", two dual-paraboloid hemispheres with exact per-sample projection" },
  { "fit_rectangle", OptionType::Choice, "axis", 0, 0, { "axis", "minimum", "square" }, "",
    "directional lights: the map's rectangle in the light plane, \"axis\" aligned with an "
    "arbitrary basis of the light direction (ch. 4.2.1), \"minimum\" the minimum-area "
    "rectangle around the hull of the receivers' tile boxes (Brabec 2003, ch. 4.2.2: fewer "
    "texels for the same density, but longer ones along one side of a square map), "
    "\"square\" the one whose longer side is shortest (the square map's coarser texel side)" },
  { "fit", OptionType::Choice, "auto", 0, 0, { "auto", "view", "scene" }, "",
    "what the maps cover: \"view\", the receivers the view samples see (densest, fitted and "
    "rendered again when the camera moves), \"scene\", every triangle of the scene as VTK's "
    "shadow pass fits (coarser, but kept while only the camera moves), or \"auto\", the scene "
    "while the camera sees all of it (the view would be as large) and the view otherwise; "
    "resm always fits the view" },
  { "lookup", OptionType::Choice, "gpu", 0, 0, { "gpu", "cpu", "gbuffer" }, "",
    "\"gpu\": compared on the GPU (a `texelFetch` of the depth and a test per tap), the maps "
    "never leave the GPU; lights with one "
    "map (directional, spot) are compared in the receivers' own shaders while they are shaded, "
    "as VTK's shadow pass does; \"cpu\": maps read back and compared in double precision with "
    "vtkSMPTools (same answers up to float rounding); \"gbuffer\": \"gpu\", always as a "
    "full-screen pass over the view samples (the same values, one pass more)" },
};

// Everything shadowmap and resm share but how big the maps are.
// The map options every shadow-map technique has (shadowmap, resm, pcss).
void ReadMapOptions(const Options& opts, vtkPenumbraShadowMapShadows* technique)
{
  technique->SetResolution(opts.Integer("resolution"));
  technique->SetBias(opts.Number("bias"));
  technique->SetSlopeBias(opts.Number("slope_bias"));
  technique->SetDepthMode(opts.Choice("depth") == 1 ? vtkPenumbraShadowMapShadows::DEPTH_MIDPOINT
                                                    : vtkPenumbraShadowMapShadows::DEPTH_LINEAR);
  technique->SetPointMode(opts.Choice("point") == 1 ? vtkPenumbraShadowMapShadows::POINT_PARABOLOID
                                                    : vtkPenumbraShadowMapShadows::POINT_CUBE);
  const int fits[] = { vtkPenumbraShadowMapShadows::FIT_AXIS,
    vtkPenumbraShadowMapShadows::FIT_MINIMUM, vtkPenumbraShadowMapShadows::FIT_SQUARE };
  technique->SetFitRectangle(fits[opts.Choice("fit_rectangle")]);
  const int fitTo[] = { vtkPenumbraShadowMapShadows::FIT_TO_AUTO,
    vtkPenumbraShadowMapShadows::FIT_TO_VIEW, vtkPenumbraShadowMapShadows::FIT_TO_SCENE };
  technique->SetFitTo(fitTo[opts.Choice("fit")]);
}

// shadowmap's and resm's: the map options, the filter and where the lookup runs.
void ReadShadowMapOptions(const Options& opts, vtkPenumbraShadowMapShadows* technique)
{
  ReadMapOptions(opts, technique);
  const int filters[] = { vtkPenumbraShadowMapShadows::FILTER_NONE,
    vtkPenumbraShadowMapShadows::FILTER_PCF, vtkPenumbraShadowMapShadows::FILTER_BILINEAR };
  technique->SetFilter(filters[opts.Choice("filter")]);
  technique->SetPCFKernel(opts.Integer("pcf_kernel"));
  const int lookups[] = { vtkPenumbraShadowMapShadows::LOOKUP_GPU,
    vtkPenumbraShadowMapShadows::LOOKUP_CPU, vtkPenumbraShadowMapShadows::LOOKUP_GBUFFER };
  technique->SetLookup(lookups[opts.Choice("lookup")]);
}

vtkSmartPointer<vtkPenumbraShadowTechnique> CreateShadowMap(const Options& opts)
{
  auto technique = vtkSmartPointer<vtkPenumbraShadowMapShadows>::New();
  ReadShadowMapOptions(opts, technique);
  return technique;
}

// RESM: shadowmap's options (resolution then only sizes point lights' faces) and the
// estimate's.
OptionTable RESMTable()
{
  OptionTable table = ShadowMapOptions;
  table[0].Doc = "point lights only (not estimated): texels per cube face or paraboloid "
                 "hemisphere";
  table.push_back({ "max_resolution", OptionType::Integer, 4096, 64, 16384, {}, "texels",
    "largest map side the estimate may choose" });
  table.push_back({ "coverage", OptionType::Number, 0.99, 0.5, 1.0, {}, "",
    "share of the view's 4 x 4-sample tiles whose samples get the resolution they need (1: the "
    "largest need, which one grazing sample drives to max_resolution)" });
  table.push_back({ "analysis_step", OptionType::Integer, 2, 1, 4, {}, "samples",
    "the estimate analyses every n-th sample per axis (n^2 times less work)" });
  return table;
}
const OptionTable RESMOptions = RESMTable();

vtkSmartPointer<vtkPenumbraShadowTechnique> CreateRESM(const Options& opts)
{
  auto technique = vtkSmartPointer<vtkPenumbraShadowMapShadows>::New();
  ReadShadowMapOptions(opts, technique);
  technique->SetResolutionMode(vtkPenumbraShadowMapShadows::RESOLUTION_ESTIMATED);
  technique->SetMaxResolution(opts.Integer("max_resolution"));
  technique->SetCoverage(opts.Number("coverage"));
  technique->SetAnalysisStep(opts.Integer("analysis_step"));
  return technique;
}

// RMSM (Lefohn et al. 2007): the virtual map's size, the physical atlas, the cache and the
// bias.
const OptionTable RMSMOptions = {
  { "max_resolution", OptionType::Integer, 32768, 2048, 32768, { 2048, 4096, 8192, 16384, 32768 },
    "texels", "effective resolution of the finest level, texels per side of the virtual map" },
  { "atlas_size", OptionType::Integer, 4096, 512, 8192, { 512, 1024, 2048, 4096, 8192 }, "texels",
    "side of the physical page atlas ((atlas_size / 32)^2 pages of 32 x 32 texels; 4 bytes a "
    "texel: 64 MiB at 4096)" },
  { "filter", OptionType::Choice, "none", 0, 0, { "none", "bilinear" }, "",
    "\"none\": the nearest texel of the requested level, 0/1; \"bilinear\": 2 x 2 PCF at "
    "that level, the taps resolved through the page table and weighted bilinearly (the "
    "paper blends two levels; this uses one)" },
  { "footprint", OptionType::Choice, "area", 0, 0, { "width", "area" }, "",
    "how a sample's footprint in the map sets its level: \"area\", the paper's Eq. 1, texels "
    "as large as the square root of its area (coarser across slanted receivers; their shadow "
    "edges are refined); \"width\", texels as small as the footprint's smallest width (more "
    "pages)" },
  { "lod_bias", OptionType::Integer, 1, 0, 2, {}, "levels",
    "request levels this much finer than the one whose texel matches a sample's footprint "
    "(0: matched, rounded up; each level quadruples the pages)" },
  { "refine", OptionType::Integer, 3, 0, 4, {}, "levels",
    "levels finer at shadow edges: the samples whose 2 x 2 texels at their level disagree "
    "request the page this much finer once the requested pages are resident (0: off)" },
  { "analysis_step", OptionType::Integer, 2, 1, 2, {}, "samples",
    "the request pass computes the level of one sample per n x n block (2: four times fewer "
    "level computations; the block's samples request their own pages at that level, those "
    "on another surface add their own level and the block takes the finest)" },
  { "cached", OptionType::Boolean, true, 0, 0, {}, "",
    "keep the pages while the light, the casters and the settings are unchanged (only new "
    "requests are rendered); false rebuilds every frame" },
  { "bias", OptionType::Number, 1e-4, 0.0, 0.1, {}, "fraction of the depth range",
    "constant depth bias as a fraction of the virtual map's depth range" },
  { "slope_bias", OptionType::Number, 0.25, 0.0, 16.0, {}, "texel footprints",
    "slope-scaled bias in texel footprints of the level a sample is compared at, on top of the "
    "receiver plane (each texel is compared with the sample's tangent plane at its centre; the "
    "slope's "
    "tangent is capped at 1000)" },
};

vtkSmartPointer<vtkPenumbraShadowTechnique> CreateRMSM(const Options& opts)
{
  auto technique = vtkSmartPointer<vtkPenumbraResolutionMatchedShadows>::New();
  technique->SetMaxResolution(opts.Integer("max_resolution"));
  technique->SetAtlasSize(opts.Integer("atlas_size"));
  technique->SetFilter(opts.Choice("filter") == 1
      ? vtkPenumbraResolutionMatchedShadows::FILTER_BILINEAR
      : vtkPenumbraResolutionMatchedShadows::FILTER_NONE);
  technique->SetFootprint(opts.Choice("footprint") == 1
      ? vtkPenumbraResolutionMatchedShadows::FOOTPRINT_AREA
      : vtkPenumbraResolutionMatchedShadows::FOOTPRINT_WIDTH);
  technique->SetLODBias(opts.Integer("lod_bias"));
  technique->SetRefineLevels(opts.Integer("refine"));
  technique->SetAnalysisStep(opts.Integer("analysis_step"));
  technique->SetCached(opts.Boolean("cached"));
  technique->SetBias(opts.Number("bias"));
  technique->SetSlopeBias(opts.Number("slope_bias"));
  return technique;
}

// PCSS: shadowmap's map options (no filter: the soft lookup is the filter) and the soft
// lookup's taps and reach (Fernando 2005).
OptionTable PCSSTable()
{
  OptionTable table;
  for (const OptionSpec& spec : ShadowMapOptions)
  {
    const std::string name = spec.Name;
    if (name != "filter" && name != "pcf_kernel" && name != "lookup")
    {
      table.push_back(spec);
    }
  }
  table.push_back({ "search_taps", OptionType::Integer, 4, 1, 16, {}, "taps per light axis",
    "blocker-search taps on a stratified grid over the light (n x n for a rectangle, 2 n for a "
    "line)" });
  table.push_back({ "filter_taps", OptionType::Integer, 6, 1, 32, {}, "taps per light axis",
    "PCF taps over the light's image at the blockers' depth (n x n for a rectangle, 2 n for a "
    "line): the number of visibility levels" });
  table.push_back({ "search_depth", OptionType::Number, 0.2, 0.01, 0.99, {},
    "fraction of the receiver's distance",
    "the nearest blocker the search looks for, as a fraction of the receiver's distance from "
    "the light (smaller: a wider search)" });
  table.push_back({ "max_radius", OptionType::Number, 64.0, 1.0, 4096.0, {}, "texels",
    "no tap lies farther from the sample (bounds the cost of huge lights)" });
  table.push_back({ "block", OptionType::Integer, 4, 1, 16, {}, "pixels",
    "adaptive sampling (Brabec 2003, ch. 11.3): search at the corners of block x block pixel "
    "blocks and interpolate where the four corners lie on the pixel's prop and share its hard "
    "shadow test; 1 searches at every pixel" });
  return table;
}
const OptionTable PCSSOptions = PCSSTable();

// Single-sample soft shadows (Brabec 2003, ch. 11): shadowmap's map options, the search box
// and the two ways of sizing the penumbra (the light's size, or the thesis's radii).
OptionTable SingleSampleTable()
{
  OptionTable table;
  for (const OptionSpec& spec : PCSSOptions)
  {
    const std::string name = spec.Name;
    if (name != "search_taps" && name != "filter_taps")
    {
      table.push_back(spec);
    }
  }
  table.push_back({ "search_taps", OptionType::Integer, 4, 1, 16, {}, "taps per half side",
    "the nearest-blocker / nearest-lit search scans a (2n + 1) x (2n + 1) box of texels around "
    "the sample (one tap per texel while the box is narrower, else spread evenly over it)" });
  table.push_back({ "physical", OptionType::Boolean, true, 0, 0, {}, "",
    "true: every penumbra from the light's own size (similar triangles through the blocker "
    "texel found, no calibration); false: the thesis's radii r_scale, r_bias, r_shrink" });
  table.push_back({ "r_scale", OptionType::Number, 4.0, 0.0, 1e6, {}, "texels per unit length",
    "physical=false: search radius grows by this per unit of the receiver's distance from the "
    "light along its axis" });
  table.push_back({ "r_bias", OptionType::Number, 0.0, 0.0, 4096.0, {}, "texels",
    "physical=false: search radius at zero distance" });
  table.push_back({ "r_shrink", OptionType::Number, 1.0, 1e-9, 1e9, {}, "per unit length",
    "physical=false: at a blocker of depth d the radius becomes r_max r_shrink (w - d), w the "
    "receiver's depth (contact shadows sharpen)" });
  return table;
}
const OptionTable SingleSampleOptions = SingleSampleTable();

// The options pcss and single-sample-soft share: the map's, the search and the adaptive
// sampling.
void ReadSoftOptions(const Options& opts, vtkPenumbraShadowMapShadows* technique, int mode)
{
  ReadMapOptions(opts, technique);
  technique->SetAreaLightMode(mode);
  technique->SetSearchTaps(opts.Integer("search_taps"));
  technique->SetSearchDepth(opts.Number("search_depth"));
  technique->SetMaxRadius(opts.Number("max_radius"));
  technique->SetAdaptiveBlock(opts.Integer("block"));
}

vtkSmartPointer<vtkPenumbraShadowTechnique> CreateSingleSample(const Options& opts)
{
  auto technique = vtkSmartPointer<vtkPenumbraShadowMapShadows>::New();
  ReadSoftOptions(opts, technique, vtkPenumbraShadowMapShadows::AREA_SINGLE_SAMPLE);
  technique->SetPhysical(opts.Boolean("physical"));
  technique->SetRScale(opts.Number("r_scale"));
  technique->SetRBias(opts.Number("r_bias"));
  technique->SetRShrink(opts.Number("r_shrink"));
  return technique;
}

vtkSmartPointer<vtkPenumbraShadowTechnique> CreatePCSS(const Options& opts)
{
  auto technique = vtkSmartPointer<vtkPenumbraShadowMapShadows>::New();
  ReadSoftOptions(opts, technique, vtkPenumbraShadowMapShadows::AREA_PCSS);
  technique->SetFilterTaps(opts.Integer("filter_taps"));
  return technique;
}

// Soft shadow maps (Brabec 2003, ch. 10): the light samples, the maps and the skins'
// threshold; the bias as shadowmap's.
const OptionTable SoftShadowMapOptions = {
  { "samples", OptionType::Integer, 3, 2, 16, {}, "light samples",
    "linear lights: samples along the line, both endpoints included (2 shows the overlap "
    "artifact of ch. 10.1.2)" },
  { "grid", OptionType::Integer, 2, 2, 4, {}, "light samples per axis",
    "rectangular lights: a k x k grid whose outer samples are the corners (2: the 4 corners), "
    "split into elements (see elements)" },
  { "elements", OptionType::Choice, "cells", 0, 0, { "cells", "triangles" }, "",
    "rectangular lights: \"cells\", per grid cell the polygon of its lit corners and the "
    "skins' split points on its edges (Ying et al.'s variant, ch. 10.1.3); \"triangles\", two "
    "triangles per cell with per-vertex visibility channels (the thesis's own)" },
  { "resolution", OptionType::Integer, 1024, 64, 4096, {}, "texels",
    "texels per side of each light sample's depth map" },
  { "fit", OptionType::Choice, "scene", 0, 0, { "scene", "view" }, "",
    "what each light sample's map covers: \"scene\", the whole scene when it lies within 85 "
    "degrees of the axis from the light to it (maps and skins kept while only the camera "
    "moves; coarser texels when the view shows part of the scene), else as \"view\"; "
    "\"view\", the visible receivers (rebuilt whenever the view changes)" },
  { "threshold", OptionType::Number, 0.02, 0.001, 1.0, {}, "fraction of the depth",
    "depth discontinuity (skin) threshold: the 3 x 3 Laplacian and the jump across a 2 x 2 "
    "cell, relative to the depth from the light sample" },
  { "bias", OptionType::Number, 5e-4, 0.0, 0.1, {}, "fraction of the depth range",
    "constant depth bias of the shadow test and the skins' depth test (1e-4 leaves acne on "
    "city_area_light's roofs)" },
  { "slope_bias", OptionType::Number, 1.0, 0.0, 16.0, {}, "texel footprints",
    "slope-scaled bias: the receiver's depth change across this many texels at its angle to "
    "the light sample" },
  { "block", OptionType::Integer, 4, 1, 16, {}, "samples",
    "lookup block side: blocks whose corners agree on full light or umbra and whose samples "
    "lie on one plane take the corners' value; 1 looks up every sample" },
};

vtkSmartPointer<vtkPenumbraShadowTechnique> CreateSoftShadowMap(const Options& opts)
{
  auto technique = vtkSmartPointer<vtkPenumbraSoftShadowMapShadows>::New();
  technique->SetNumberOfLineSamples(opts.Integer("samples"));
  technique->SetGridSamples(opts.Integer("grid"));
  technique->SetElements(opts.Choice("elements") == 1
      ? vtkPenumbraSoftShadowMapShadows::ELEMENTS_TRIANGLES
      : vtkPenumbraSoftShadowMapShadows::ELEMENTS_CELLS);
  technique->SetResolution(opts.Integer("resolution"));
  technique->SetFit(opts.Choice("fit") == 1 ? vtkPenumbraSoftShadowMapShadows::FIT_VIEW
                                            : vtkPenumbraSoftShadowMapShadows::FIT_SCENE);
  technique->SetThreshold(opts.Number("threshold"));
  technique->SetBias(opts.Number("bias"));
  technique->SetSlopeBias(opts.Number("slope_bias"));
  technique->SetBlock(opts.Integer("block"));
  return technique;
}

}

// The descriptions cite the papers by short name:
// - Brabec 2003: Brabec, "Shadow Techniques for Interactive and Real-Time Applications", PhD
//   thesis, 2003;
// - Ferko 2013: Ferko, resolution-estimation shadow mapping (RESM), in the alias-free shadow
//   mapping work of his doctoral thesis (Comenius University Bratislava);
// - Lefohn et al. 2007: Lefohn, Sengupta, Owens, "Resolution-Matched Shadow Maps", ACM TOG
//   26(4), 2007;
// - Fernando 2005: Fernando, "Percentage-Closer Soft Shadows", SIGGRAPH 2005 Sketches.
const penumbra_options::TechniqueList& penumbra_shadow_maps::Techniques()
{
  static const TechniqueList techniques = {
    { "shadowmap",
      "practical shadow maps (Brabec 2003, ch. 4-6): linear 32-bit float depth fitted to the "
      "visible receivers with depth clamping, PCF, Woo's midpoint depth, cube or dual-paraboloid "
      "maps for point lights; point, spot and directional lights",
      ShadowMapOptions, CreateShadowMap },
    { "resm",
      "shadow maps at the resolution the view samples need (RESM, Ferko 2013): the tight fit of "
      "shadowmap, per light and axis the size at which a texel covers at most a pixel, up to "
      "max_resolution; directional and spot lights (point lights: shadowmap's fixed size)",
      RESMOptions, CreateRESM },
    { "rmsm",
      "resolution-matched shadow maps (Lefohn et al. 2007): per view sample the level of a "
      "virtual map up to max_resolution^2 whose texel matches the sample's footprint, only the "
      "requested 32 x 32 pages rendered (by superpage) into a page atlas, kept while the light "
      "and casters stay put; directional and spot lights (up to 60 degrees)",
      RMSMOptions, CreateRMSM },
    { "pcss",
      "percentage-closer soft shadows (Fernando 2005) from area and linear lights: one "
      "perspective map from the light's centre, a blocker search and a PCF kernel shaped like "
      "the light's image in the map; other lights get shadowmap's hard shadows",
      PCSSOptions, CreatePCSS },
    { "single-sample-soft",
      "single-sample soft shadows (Brabec 2003, ch. 11) from area and linear lights: one "
      "perspective map from the light's centre, the nearest blocker (outer penumbra) or nearest "
      "lit texel (inner penumbra) in a box around each sample; other lights get shadowmap's hard "
      "shadows",
      SingleSampleOptions, CreateSingleSample },
    { "soft-shadowmap",
      "soft shadow maps (Brabec 2003, ch. 10) from area and linear lights: a depth map per light "
      "sample (line: endpoints and interior samples; rectangle: corner grid), skins across "
      "depth discontinuities warped into the neighbouring samples' maps as visibility channels; "
      "other lights get shadowmap's hard shadows",
      SoftShadowMapOptions, CreateSoftShadowMap },
  };
  return techniques;
}
