#include "vtkPenumbraShadowTechnique.h"

void vtkPenumbraShadowTechnique::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "LastTimeMs: " << this->LastTimeMs << "\n";
}
