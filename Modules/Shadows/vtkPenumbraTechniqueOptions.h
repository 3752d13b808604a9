/**
 * @file    vtkPenumbraTechniqueOptions.h
 * @brief   Part of the contract: how a technique family describes its techniques to the
 *          registry.
 *
 * Each family (ShadowMaps, ExactShadows, Gears) lists its techniques as TechniqueInfo rows:
 * the name users type, a one-line description citing the paper, one option table and a
 * factory that makes the technique configured by validated options. The registry
 * (vtkPenumbraTechniques) collects the families' lists and installs what a factory makes;
 * validation, `penumbra-render --list-techniques`, the scene schema's option tables, the
 * ParaView properties and the Python docstrings all come from the tables (the pbrt-v4 rule:
 * each option and its default named once).
 */

#ifndef vtkPenumbraTechniqueOptions_h
#define vtkPenumbraTechniqueOptions_h

#ifndef __VTK_WRAP__

#include "vtkPenumbraShadowsModule.h" // For export macro
#include "vtkSmartPointer.h"          // For TechniqueInfo::Create

#include <nlohmann/json.hpp> // For option values

#include <functional> // For TechniqueInfo::Create
#include <stdexcept>  // For OptionError
#include <string>     // For messages
#include <vector>     // For tables

class vtkPenumbraShadowTechnique;

namespace penumbra_options
{
using json = nlohmann::json;

/// A bad option (unknown name, wrong type, out of range): its text names the option.
struct OptionError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

enum class OptionType
{
  Integer,
  Number,
  Boolean,
  Choice
};

/// One row of a technique's option table.
struct OptionSpec
{
  const char* Name;
  OptionType Type;
  json Default;
  double Min = 0.0; // Integer, Number: inclusive range
  double Max = 0.0;
  std::vector<json> Values = {}; // Choice: the strings; Integer: the only values allowed, if any
  const char* Unit = "";
  const char* Doc = "";
};

using OptionTable = std::vector<OptionSpec>;

/// "integer", "number", "boolean" or "choice".
VTKPENUMBRASHADOWS_EXPORT const char* TypeName(OptionType type);

/// "64..8192", "0, 4, 8, 16, 32", "\"cpu\", \"gpu\"" or "true, false".
VTKPENUMBRASHADOWS_EXPORT std::string RangeText(const OptionSpec& spec);

/**
 * Checks options `j` against a technique's table: known names only, each value of its type
 * and in its range (OptionError otherwise). Values are then read by name; an absent option
 * gives the table's default. `j` and `table` must outlive the object.
 */
class VTKPENUMBRASHADOWS_EXPORT Options
{
public:
  Options(const json& j, const OptionTable& table);

  int Integer(const char* key) const;
  double Number(const char* key) const;
  bool Boolean(const char* key) const;
  /// The index of the chosen value in the option's choices.
  int Choice(const char* key) const;

private:
  const OptionSpec& Spec(const char* key) const;
  const json& Value(const char* key) const;
  void RejectUnknown() const;

  const json& J;
  const OptionTable& Table;
};

/// A technique as its family describes it to the registry.
struct TechniqueInfo
{
  const char* Name;
  const char* Description;
  OptionTable Table;
  /// The technique configured by `options` (checked against Table); may throw OptionError.
  std::function<vtkSmartPointer<vtkPenumbraShadowTechnique>(const Options& options)> Create;
};

using TechniqueList = std::vector<TechniqueInfo>;

/**
 * Light samples per axis for area and linear lights, shared by the techniques that sample
 * lights (raytraced, adaptive-soft, gears, auto): 0 keeps the light's own k; otherwise one
 * of the values Wang et al. measure ("GEARS: A General and Efficient Algorithm for Rendering
 * Shadows", Computer Graphics Forum 33(6), 2014), so techniques compare at equal k.
 */
VTKPENUMBRASHADOWS_EXPORT const OptionSpec& SamplesOption();
}

#endif // __VTK_WRAP__
#endif
