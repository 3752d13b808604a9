/**
 * @class   vtkSIPenumbraLightSizeProperty
 * @brief   Server side of a ParaView light's size for Penumbra's soft shadows.
 *
 * ParaView's light proxy (additional_lights/Light, class vtkPVLight) has a Radius property
 * whose command, vtkPVLight::SetRadius, keeps the radius only for OSPRay: a ParaView built
 * without ray tracing (Debian's) drops it and its GUI hides the property; vtkPVLight is made
 * with plain `new`, so no subclass can stand in for it, and the client-server interpreter
 * refuses a second command function for it. The plugin's PenumbraLight.xml therefore extends
 * the light proxy with ShadowRadius (shown in the GUI's light inspector), whose server side is
 * this class (si_class): it sets the light's vtkPenumbraShadowKeys::LIGHT_RADIUS on every
 * process, and the shadow pass shadows a positional light with a radius as its disc
 * (vtkPenumbraAreaLight::SetFromLightRadius).
 */

#ifndef vtkSIPenumbraLightSizeProperty_h
#define vtkSIPenumbraLightSizeProperty_h

#include "vtkPenumbraParaViewViewModule.h" // For export macro
#include "vtkSIDoubleVectorProperty.h"

class VTKPENUMBRAPARAVIEWVIEW_EXPORT vtkSIPenumbraLightSizeProperty
  : public vtkSIDoubleVectorProperty
{
public:
  static vtkSIPenumbraLightSizeProperty* New();
  vtkTypeMacro(vtkSIPenumbraLightSizeProperty, vtkSIDoubleVectorProperty);
  void PrintSelf(ostream& os, vtkIndent indent) override;

protected:
  vtkSIPenumbraLightSizeProperty() = default;
  ~vtkSIPenumbraLightSizeProperty() override = default;

  // The light's radius from the pushed value (the property has no command).
  bool Push(vtkSMMessage* message, int offset) override;

private:
  vtkSIPenumbraLightSizeProperty(const vtkSIPenumbraLightSizeProperty&) = delete;
  void operator=(const vtkSIPenumbraLightSizeProperty&) = delete;
};

#endif
