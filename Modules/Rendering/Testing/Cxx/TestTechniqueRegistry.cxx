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
  return EXIT_SUCCESS;
}
