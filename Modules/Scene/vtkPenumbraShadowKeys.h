/**
 * @class   vtkPenumbraShadowKeys
 * @brief   Per-prop shadow flags: does a prop cast shadows, does it receive them.
 *
 * The flags live in the prop's property keys (vtkProp::GetPropertyKeys()), the same place
 * VTK's shadow passes used for their OCCLUDER/RECEIVER keys before 9.x removed them, so an
 * application marks props without knowing which technique will run:
 *
 * @code
 * vtkPenumbraShadowKeys::SetCastsShadows(actor, false);
 * @endcode
 *
 * A prop without the keys both casts and receives. Every technique and the exact reference
 * read the flags through this class.
 */

#ifndef vtkPenumbraShadowKeys_h
#define vtkPenumbraShadowKeys_h

#include "vtkObject.h"
#include "vtkPenumbraSceneModule.h" // For export macro

class vtkInformationIntegerKey;
class vtkProp;

class VTKPENUMBRASCENE_EXPORT vtkPenumbraShadowKeys : public vtkObject
{
public:
  static vtkPenumbraShadowKeys* New();
  vtkTypeMacro(vtkPenumbraShadowKeys, vtkObject);

  /**
   * 1 (default when absent): the prop's geometry blocks light. 0: it does not.
   */
  static vtkInformationIntegerKey* OCCLUDER();

  /**
   * 1 (default when absent): shadows darken the prop. 0: it is lit as if nothing blocked.
   */
  static vtkInformationIntegerKey* RECEIVER();

  static bool CastsShadows(vtkProp* prop);
  static bool ReceivesShadows(vtkProp* prop);
  static void SetCastsShadows(vtkProp* prop, bool casts);
  static void SetReceivesShadows(vtkProp* prop, bool receives);

protected:
  vtkPenumbraShadowKeys() = default;
  ~vtkPenumbraShadowKeys() override = default;

private:
  vtkPenumbraShadowKeys(const vtkPenumbraShadowKeys&) = delete;
  void operator=(const vtkPenumbraShadowKeys&) = delete;
};

#endif
