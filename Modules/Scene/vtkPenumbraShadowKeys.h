/**
 * @class   vtkPenumbraShadowKeys
 * @brief   Per-prop shadow flags (does a prop cast shadows, does it receive them) and the
 *          size of a light.
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
 *
 * A light's size lives in its information (vtkLight::GetInformation()), LIGHT_RADIUS:
 *
 * @code
 * vtkPenumbraShadowKeys::SetLightRadius(pointLight, 0.25); // a sphere of radius 0.25
 * @endcode
 *
 * vtkPenumbraShadowPass shadows a positional light with a radius as the disc of that radius
 * facing its focal point (vtkPenumbraAreaLight::SetFromLightRadius), so the soft techniques
 * draw its penumbra and the hard ones follow the pass's rule for area lights.
 */

#ifndef vtkPenumbraShadowKeys_h
#define vtkPenumbraShadowKeys_h

#include "vtkObject.h"
#include "vtkPenumbraSceneModule.h" // For export macro

class vtkInformationDoubleKey;
class vtkInformationIntegerKey;
class vtkLight;
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

  /**
   * Radius of a positional light's emitting sphere in world units; absent or 0: a point
   * light. Ignored on vtkPenumbraAreaLight (its own size counts) and on directional lights.
   */
  static vtkInformationDoubleKey* LIGHT_RADIUS();

  /**
   * The light's LIGHT_RADIUS, 0 when absent (or no light).
   */
  static double GetLightRadius(vtkLight* light);

  /**
   * Sets LIGHT_RADIUS (removes it for 0) and marks the light modified. Negative or NaN
   * radii are stored as given and refused by the pass with a message.
   */
  static void SetLightRadius(vtkLight* light, double radius);

protected:
  vtkPenumbraShadowKeys() = default;
  ~vtkPenumbraShadowKeys() override = default;

private:
  vtkPenumbraShadowKeys(const vtkPenumbraShadowKeys&) = delete;
  void operator=(const vtkPenumbraShadowKeys&) = delete;
};

#endif
