/**
 * @class   vtkPenumbraTechniques
 * @brief   Registry of shadow techniques: installs one, by name, on a renderer.
 *
 * Every way Penumbra can draw shadows is registered here under a short name, with a
 * documented set of options. Applications, the scene files' "technique" block, the
 * `penumbra-render --technique` switch and the benchmark all go through Apply(), so a
 * technique is available everywhere once its family lists it.
 *
 * The registered techniques are not listed here: `penumbra-render --list-techniques` prints
 * every one with its options (GetTechniqueName() and the option accessors below), and
 * docs/architecture.md ("Registry name -> folder and class") says where each lives. This
 * file defines three of them, `none`, `auto` (the default of scene files, the CLI, the
 * examples and the Python helper; see vtkPenumbraAutoShadows) and `vtk-shadowmap` (VTK's own
 * pass, the peer); every other one comes from its family's list, described beside its
 * classes (penumbra_exact_shadows::Techniques(), penumbra_shadow_maps::Techniques(),
 * penumbra_gears::Techniques(); see vtkPenumbraTechniqueOptions.h). Each has one option
 * table (name, type, default, range or choices, unit, one-line doc); Apply() validates
 * against it, and the option accessors below, `penumbra-render --list-techniques`, the
 * option section of Data/Scenes/SCHEMA.md (GetOptionsMarkdown()) and the Python docstrings
 * are produced from it.
 *
 * Options are JSON text (an object); unknown options and out-of-range values are rejected
 * with a message naming the option.
 *
 * Papers (docs/techniques.md says what each technique changes):
 * - Hertel, Hormann, Westermann, "A Hybrid GPU Rendering Pipeline for Alias-Free Hard
 *   Shadows", Eurographics 2009 Areas Papers.
 * - Brabec, "Shadow Techniques for Interactive and Real-Time Applications", PhD thesis, 2003.
 * - Wang, Wang, Shi, Popescu, "GEARS: A General and Efficient Algorithm for Rendering
 *   Shadows", Computer Graphics Forum 33(6), 2014.
 */

#ifndef vtkPenumbraTechniques_h
#define vtkPenumbraTechniques_h

#include "vtkObject.h"
#include "vtkPenumbraTechniquesModule.h" // For export macro

#include <string> // For std::string
#include <vector> // For std::vector

class vtkRenderer;

class VTKPENUMBRATECHNIQUES_EXPORT vtkPenumbraTechniques : public vtkObject
{
public:
  static vtkPenumbraTechniques* New();
  vtkTypeMacro(vtkPenumbraTechniques, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The registered technique names and one-line descriptions.
   */
  static int GetNumberOfTechniques();
  static const char* GetTechniqueName(int index);
  static const char* GetTechniqueDescription(int index);
  static bool HasTechnique(const char* name);
  ///@}

  /**
   * The technique an application should start with when its user names none: `auto`, the
   * default of scene files, the CLI, the examples and the Python helper.
   */
  static const char* GetDefaultTechnique();

  ///@{
  /**
   * Technique `technique`'s option table, row `index` in [0, GetNumberOfOptions()):
   * the option's name, type ("integer", "number", "boolean" or "choice"), default as JSON
   * text, range ("64..8192") or choices ("\"cpu\", \"gpu\""), unit ("" when unit-free) and a
   * one-line doc. Unknown techniques have no options; a row out of range gives nullptr / "".
   */
  static int GetNumberOfOptions(const char* technique);
  static const char* GetOptionName(const char* technique, int index);
  static const char* GetOptionType(const char* technique, int index);
  static std::string GetOptionDefault(const char* technique, int index);
  static std::string GetOptionRange(const char* technique, int index);
  static const char* GetOptionUnit(const char* technique, int index);
  static const char* GetOptionDoc(const char* technique, int index);
  ///@}

  /**
   * The inclusive range of an integer or number option, for tools that build their own
   * widgets (the ParaView plugin); false for booleans, choices and integers limited to a list.
   */
  static bool GetOptionBounds(const char* technique, int index, double bounds[2]);

#ifndef __VTK_WRAP__
  /**
   * The values a choice option, or an integer option limited to a list, allows, each as JSON
   * text ("\"cpu\"", "8"); empty for other options.
   */
  static std::vector<std::string> GetOptionChoices(const char* technique, int index);
#endif

  /**
   * Every technique with its description and options, as `penumbra-render --list-techniques`
   * prints it.
   */
  static std::string GetTechniqueList();

  /**
   * The technique section of Data/Scenes/SCHEMA.md (Markdown, one table per technique);
   * a test compares the committed file with it.
   */
  static std::string GetOptionsMarkdown();

  /**
   * Makes `renderer` draw with technique `name` configured by `options` (JSON object text;
   * nullptr or "" means defaults). Returns 1 on success; 0 leaves the renderer unchanged and
   * sets GetErrorMessage() to "<option>: <problem>" or "unknown technique ...".
   */
  int Apply(vtkRenderer* renderer, const char* name, const char* options);

  /**
   * Why the last Apply() failed; empty after a success.
   */
  const char* GetErrorMessage()
  {
    return this->ErrorMessage.c_str();
  }

protected:
  vtkPenumbraTechniques() = default;
  ~vtkPenumbraTechniques() override = default;

private:
  vtkPenumbraTechniques(const vtkPenumbraTechniques&) = delete;
  void operator=(const vtkPenumbraTechniques&) = delete;

  std::string ErrorMessage;
};

#endif
