/**
 * @file    vtkPenumbraExactTechniques.h
 * @brief   The exact family's techniques as the registry lists them: raytraced, adaptive-soft,
 * conservative, llsm, llsm-hybrid, volumes (name, description, option table, factory; see
 * vtkPenumbraTechniqueOptions.h).
 */

#ifndef vtkPenumbraExactTechniques_h
#define vtkPenumbraExactTechniques_h

#ifndef __VTK_WRAP__
#include "vtkPenumbraExactShadowsModule.h" // For export macro
#include "vtkPenumbraTechniqueOptions.h"   // For TechniqueList

namespace penumbra_exact_shadows
{
/// This family's techniques, in the order the registry lists them.
VTKPENUMBRAEXACTSHADOWS_EXPORT const penumbra_options::TechniqueList& Techniques();
}
#endif

#endif
