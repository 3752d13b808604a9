// The technique registry: names are unique, options are validated, a failed Apply leaves the
// renderer as it was.
#include "vtkNew.h"
#include "vtkPenumbraTechniques.h"
#include "vtkRenderPass.h"
#include "vtkRenderer.h"

#include <cstdlib>
#include <cstring>
#include <iostream>
#include <set>
#include <string>

#include "PenumbraTestMacros.h"

int TestTechniqueRegistry(int, char*[])
{
  std::set<std::string> names;
  for (int i = 0; i < vtkPenumbraTechniques::GetNumberOfTechniques(); ++i)
  {
    CHECK(names.insert(vtkPenumbraTechniques::GetTechniqueName(i)).second);
    CHECK(std::strlen(vtkPenumbraTechniques::GetTechniqueDescription(i)) > 0);
  }
  CHECK(names.count("none") && names.count("vtk-shadowmap"));
  CHECK(vtkPenumbraTechniques::GetTechniqueName(-1) == nullptr);
  CHECK(!vtkPenumbraTechniques::HasTechnique("nope") && !vtkPenumbraTechniques::HasTechnique(nullptr));

  vtkNew<vtkPenumbraTechniques> t;
  vtkNew<vtkRenderer> ren;
  CHECK(t->Apply(ren, "vtk-shadowmap", R"({"resolution": 512})"));
  vtkRenderPass* installed = ren->GetPass();
  CHECK(installed != nullptr);

  const char* bad[] = { R"({"resolution": 8})", R"({"resolution": 1.5})", R"({"bias": 1})",
    "[1, 2]", "{not json" };
  for (const char* options : bad)
  {
    CHECK(!t->Apply(ren, "vtk-shadowmap", options));
    CHECK(std::strlen(t->GetErrorMessage()) > 0);
    CHECK(ren->GetPass() == installed); // unchanged
  }
  CHECK(!t->Apply(ren, "none", R"({"resolution": 512})"));
  CHECK(std::string(t->GetErrorMessage()).find("has none") != std::string::npos);
  CHECK(t->Apply(ren, "none", ""));
  CHECK(ren->GetPass() == nullptr);
  CHECK(!t->Apply(nullptr, "none", ""));

  // Every table row is documented, and its default passes its own validation.
  for (int i = 0; i < vtkPenumbraTechniques::GetNumberOfTechniques(); ++i)
  {
    const char* name = vtkPenumbraTechniques::GetTechniqueName(i);
    std::string defaults;
    for (int o = 0; o < vtkPenumbraTechniques::GetNumberOfOptions(name); ++o)
    {
      CHECK(std::strlen(vtkPenumbraTechniques::GetOptionDoc(name, o)) > 0);
      CHECK(!vtkPenumbraTechniques::GetOptionRange(name, o).empty());
      defaults += (defaults.empty() ? "{" : ", ") + std::string("\"") +
        vtkPenumbraTechniques::GetOptionName(name, o) +
        "\": " + vtkPenumbraTechniques::GetOptionDefault(name, o);
    }
    defaults += defaults.empty() ? "{}" : "}";
    vtkNew<vtkRenderer> fresh;
    CHECK(t->Apply(fresh, name, defaults.c_str()));
  }
  CHECK(vtkPenumbraTechniques::GetOptionName("shadowmap", 99) == nullptr);
  CHECK(vtkPenumbraTechniques::GetNumberOfOptions("nope") == 0);
  // Allowed-value lists and ranges from the tables.
  CHECK(!t->Apply(ren, "raytraced", R"({"samples": 5})"));
  CHECK(std::string(t->GetErrorMessage()) == "samples: expected one of 0, 4, 8, 16, 32, got 5");
  CHECK(!t->Apply(ren, "shadowmap", R"({"pcf_kernel": 4})"));
  CHECK(!t->Apply(ren, "gears", R"({"path": "fpga"})"));
  CHECK(std::string(t->GetErrorMessage()) ==
    R"(path: expected one of "auto", "cpu", "gpu", got "fpga")");
  return EXIT_SUCCESS;
}
