/**
 * @file    vtkPenumbraShadowMapTechniques.h
 * @brief   The shadow-map family's techniques as the registry lists them: shadowmap, resm, rmsm,
 * pcss, single-sample-soft, soft-shadowmap (name, description, option table, factory; see
 * vtkPenumbraTechniqueOptions.h).
 */

#ifndef vtkPenumbraShadowMapTechniques_h
#define vtkPenumbraShadowMapTechniques_h

#ifndef __VTK_WRAP__
#include "vtkPenumbraShadowMapsModule.h" // For export macro
#include "vtkPenumbraTechniqueOptions.h" // For TechniqueList

namespace penumbra_shadow_maps
{
/// This family's techniques, in the order the registry lists them.
VTKPENUMBRASHADOWMAPS_EXPORT const penumbra_options::TechniqueList& Techniques();
}
#endif

#endif
