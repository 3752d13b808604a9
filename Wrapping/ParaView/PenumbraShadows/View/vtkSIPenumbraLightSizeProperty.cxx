#include "vtkSIPenumbraLightSizeProperty.h"

#include "vtkLight.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkSMMessage.h"

vtkStandardNewMacro(vtkSIPenumbraLightSizeProperty);

bool vtkSIPenumbraLightSizeProperty::Push(vtkSMMessage* message, int offset)
{
  if (!this->Superclass::Push(message, offset))
  {
    return false;
  }
  auto* light = vtkLight::SafeDownCast(this->GetVTKObject());
  const ProxyState_Property& property = message->GetExtension(ProxyState::property, offset);
  if (!light || property.value().float64_size() != 1)
  {
    return true;
  }
  vtkPenumbraShadowKeys::SetLightRadius(light, property.value().float64(0));
  return true;
}

void vtkSIPenumbraLightSizeProperty::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
