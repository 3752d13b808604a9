// An exact technique's shadow mask does not depend on the window system: `raytraced` gives
// the same visibility, sample for sample, in an EGL and in an OSMesa window. This is what
// lets a regression-image baseline made on one build machine hold on another.
#include "vtkFloatArray.h"
#include "vtkNew.h"
#include "vtkPenumbraEGLRenderWindow.h"
#include "vtkPenumbraOSMesaRenderWindow.h"
#include "vtkPenumbraSceneReader.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraTechniques.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"

#include "PenumbraTechniqueTests.h"
#include "PenumbraTestMacros.h"

#include <vector>

namespace
{
// Renders default.json with `raytraced` in `window` (128 x 96); returns light 0's visibility.
std::vector<float> Visibility(vtkRenderWindow* window)
{
  using namespace penumbra_technique_tests;
  vtkNew<vtkPenumbraSceneReader> reader;
  vtkSmartPointer<vtkRenderer> renderer = ReadScene("default.json", reader);
  vtkNew<vtkPenumbraTechniques> techniques;
  if (!renderer || !techniques->Apply(renderer, "raytraced", "{}"))
  {
    return {};
  }
  window->SetSize(128, 96);
  window->SetMultiSamples(0);
  window->AddRenderer(renderer);
  window->Render();
  vtkPenumbraShadowPass* pass = ShadowPass(renderer);
  vtkFloatArray* factor = pass ? pass->GetVisibility(0) : nullptr;
  std::vector<float> out;
  for (vtkIdType i = 0; factor && i < factor->GetNumberOfValues(); ++i)
  {
    out.push_back(factor->GetValue(i));
  }
  window->RemoveRenderer(renderer);
  window->Finalize();
  return out;
}
}

int TestHeadlessWindowsAgree(int, char*[])
{
  vtkNew<vtkPenumbraEGLRenderWindow> egl;
  const std::vector<float> a = Visibility(egl);
  vtkNew<vtkPenumbraOSMesaRenderWindow> osmesa;
  const std::vector<float> b = Visibility(osmesa);
  CHECK(a.size() == 128u * 96u);
  CHECK(a.size() == b.size());
  size_t lit = 0, shadowed = 0, differ = 0;
  for (size_t i = 0; i < a.size(); ++i)
  {
    lit += a[i] > 0.5f ? 1 : 0;
    shadowed += a[i] < 0.5f ? 1 : 0;
    differ += a[i] != b[i] ? 1 : 0;
  }
  std::cout << "samples " << a.size() << ": lit " << lit << " shadowed " << shadowed
            << ", EGL and OSMesa differ in " << differ << std::endl;
  // Both kinds of samples occur, so equality means something.
  CHECK(lit > 100 && shadowed > 100);
  CHECK(differ == 0);
  return EXIT_SUCCESS;
}
