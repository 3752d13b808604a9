// GEARS as the registry lists it: its option table and factory, beside the class they
// configure.
#include "vtkPenumbraGearsTechniques.h"

#include "vtkPenumbraGearsShadows.h"

namespace
{
using namespace penumbra_options;

const OptionTable GearsOptions = {
  SamplesOption(),
  { "grid", OptionType::Integer, 128, 1, 4096, {}, "cells per side",
    "grid cells per side over the projected view samples; only speed depends on it" },
  { "camera_distance", OptionType::Number, 1.0, 0.01, 100.0, {}, "light diagonals",
    "distance of the grid camera behind the light centre; only the tightness of the blocker "
    "lists depends on it" },
  { "trace_threshold", OptionType::Number, 0.5, 0.0, 1e6, {}, "triangles per light sample",
    "a cell whose blocker list is longer than this times k^2 has its samples ray traced whole "
    "instead of masked; 0 masks every cell, as the compute path always does; only speed "
    "depends on it" },
  { "dense", OptionType::Choice, "trace", 0, 0, { "trace", "tree" }, "",
    "the samples of a cell above trace_threshold: \"trace\" ray traces them whole, \"tree\" "
    "masks them from a walk of a bounding volume hierarchy over the casters that skips nodes "
    "whose light samples are blocked already (slower than \"trace\" on llvmpipe); only "
    "speed depends on it" },
  { "path", OptionType::Choice, "auto", 0, 0, { "auto", "cpu", "gpu" }, "",
    "where the per-sample masks are built: \"auto\" (the CPU, the faster path on Mesa "
    "llvmpipe), \"cpu\" (vtkSMPTools) or \"gpu\" (a GL 4.3 compute shader, k <= 32); the same "
    "visibility bit for bit, and the CPU answers where the compute path cannot run" },
};

vtkSmartPointer<vtkPenumbraShadowTechnique> CreateGears(const Options& opts)
{
  const int path = opts.Choice("path");
  auto technique = vtkSmartPointer<vtkPenumbraGearsShadows>::New();
  technique->SetPath(path == 2 ? vtkPenumbraGearsShadows::PATH_GPU
      : path == 1              ? vtkPenumbraGearsShadows::PATH_CPU
                               : vtkPenumbraGearsShadows::PATH_AUTO);
  technique->SetSamplesPerAxis(opts.Integer("samples"));
  technique->SetGridResolution(opts.Integer("grid"));
  technique->SetCameraDistanceFactor(opts.Number("camera_distance"));
  technique->SetTraceThreshold(opts.Number("trace_threshold"));
  technique->SetDenseCells(opts.Choice("dense") == 1 ? vtkPenumbraGearsShadows::DENSE_TREE
                                                     : vtkPenumbraGearsShadows::DENSE_TRACE);
  return technique;
}

}

// The descriptions cite the papers by short name:
// - Wang et al. 2014: Wang, Wang, Shi, Popescu, "GEARS: A General and Efficient Algorithm for
//   Rendering Shadows", Computer Graphics Forum 33(6), 2014.
const penumbra_options::TechniqueList& penumbra_gears::Techniques()
{
  static const TechniqueList techniques = {
    { "gears",
      "exact soft shadows from area and linear lights (GEARS, Wang et al. 2014): per-cell lists of "
      "potential blockers, k x k light-sample masks built on the CPU or by a compute shader; "
      "other lights are ray traced",
      GearsOptions, CreateGears },
  };
  return techniques;
}
