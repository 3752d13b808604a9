/**
 * @file    vtkPenumbraGearsTechniques.h
 * @brief   GEARS as the registry lists it (name, description, option table, factory; see
 * vtkPenumbraTechniqueOptions.h).
 */

#ifndef vtkPenumbraGearsTechniques_h
#define vtkPenumbraGearsTechniques_h

#ifndef __VTK_WRAP__
#include "vtkPenumbraGearsModule.h"      // For export macro
#include "vtkPenumbraTechniqueOptions.h" // For TechniqueList

namespace penumbra_gears
{
/// This family's techniques, in the order the registry lists them.
VTKPENUMBRAGEARS_EXPORT const penumbra_options::TechniqueList& Techniques();
}
#endif

#endif
