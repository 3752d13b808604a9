#include "vtkPVPenumbraShadowView.h"

#include "vtkCameraPass.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPVSynchronizedRenderer.h"
#include "vtkPenumbraTechniques.h"
#include "vtkRenderPass.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkStringArray.h"

#include <limits>

// Defined by the Penumbra::Headless module: registers the EGL window (and a generic
// interactor) when no X display is set. ParaView creates its render windows through VTK's
// object factory, so this must happen before the first view exists: at plugin load, when this
// library's static objects are constructed.
void vtkPenumbraHeadless_AutoInit_Construct();

namespace
{
struct RegisterHeadlessWindow
{
  RegisterHeadlessWindow() { vtkPenumbraHeadless_AutoInit_Construct(); }
};
const RegisterHeadlessWindow registerHeadlessWindow;
}

struct vtkPVPenumbraShadowView::Internals
{
  vtkSmartPointer<vtkRenderPass> Pass;
  vtkNew<vtkStringArray> Names;
};

vtkStandardNewMacro(vtkPVPenumbraShadowView);

vtkPVPenumbraShadowView::vtkPVPenumbraShadowView()
  : Technique(vtkPenumbraTechniques::GetDefaultTechnique())
  , Impl(new Internals)
{
  this->LODRenderingThreshold = std::numeric_limits<double>::max();
}

vtkPVPenumbraShadowView::~vtkPVPenumbraShadowView()
{
  if (this->Impl->Pass && this->GetRenderWindow())
  {
    this->Impl->Pass->ReleaseGraphicsResources(this->GetRenderWindow());
  }
}

void vtkPVPenumbraShadowView::SetShadowTechnique(const char* name)
{
  const std::string value = name ? name : "";
  if (value != this->Technique)
  {
    this->Technique = value;
    this->Modified();
  }
}

void vtkPVPenumbraShadowView::SetShadowOptions(const char* options)
{
  const std::string value = options ? options : "";
  if (value != this->Options)
  {
    this->Options = value;
    this->Modified();
  }
}

vtkStringArray* vtkPVPenumbraShadowView::GetShadowTechniqueNames()
{
  vtkStringArray* names = this->Impl->Names;
  names->Initialize();
  const std::string preferred = vtkPenumbraTechniques::GetDefaultTechnique();
  names->InsertNextValue(preferred);
  for (int i = 0; i < vtkPenumbraTechniques::GetNumberOfTechniques(); ++i)
  {
    if (preferred != vtkPenumbraTechniques::GetTechniqueName(i))
    {
      names->InsertNextValue(vtkPenumbraTechniques::GetTechniqueName(i));
    }
  }
  return names;
}

const char* vtkPVPenumbraShadowView::GetShadowTechniqueHelp()
{
  this->Help = vtkPenumbraTechniques::GetTechniqueList();
  return this->Help.c_str();
}

void vtkPVPenumbraShadowView::SetLODRenderingThreshold(double)
{
  this->Superclass::SetLODRenderingThreshold(std::numeric_limits<double>::max());
}

void vtkPVPenumbraShadowView::UpdateShadowPass()
{
  // Tried once per change: a refused request is reported once, not at every render.
  if (this->Tried && this->Technique == this->TriedTechnique && this->Options == this->TriedOptions)
  {
    return;
  }
  this->Tried = true;
  this->TriedTechnique = this->Technique;
  this->TriedOptions = this->Options;
  // The registry builds camera pass -> technique pass on a renderer; ParaView brings its own
  // camera pass, so only the delegate is handed over ("none" installs no pass at all, and
  // ParaView then uses its default pass).
  const std::string name =
    this->Technique.empty() ? vtkPenumbraTechniques::GetDefaultTechnique() : this->Technique;
  vtkNew<vtkRenderer> scratch;
  vtkNew<vtkPenumbraTechniques> techniques;
  if (!techniques->Apply(scratch, name.c_str(), this->Options.c_str()))
  {
    vtkErrorMacro("Penumbra shadows: technique \""
      << name << "\" with options \"" << this->Options
      << "\" refused: " << techniques->GetErrorMessage() << "; still drawing with \""
      << this->InstalledTechnique << "\"");
    return;
  }
  vtkCameraPass* camera = vtkCameraPass::SafeDownCast(scratch->GetPass());
  vtkRenderPass* pass = camera ? camera->GetDelegatePass() : scratch->GetPass();
  if (this->Impl->Pass && this->Impl->Pass != pass && this->GetRenderWindow())
  {
    this->Impl->Pass->ReleaseGraphicsResources(this->GetRenderWindow());
  }
  this->Impl->Pass = pass;
  this->SynchronizedRenderers->SetRenderPass(pass);
  this->InstalledTechnique = name;
}

void vtkPVPenumbraShadowView::Render(bool interactive, bool skip_rendering)
{
  this->UpdateShadowPass();
  this->Superclass::Render(interactive, skip_rendering);
}

void vtkPVPenumbraShadowView::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "ShadowTechnique: " << this->Technique << "\n";
  os << indent << "ShadowOptions: " << this->Options << "\n";
  os << indent << "InstalledTechnique: " << this->InstalledTechnique << "\n";
}
