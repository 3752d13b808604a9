#include "vtkPenumbraShadowKeys.h"

#include "vtkInformation.h"
#include "vtkInformationDoubleKey.h"
#include "vtkInformationIntegerKey.h"
#include "vtkLight.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkProp.h"

vtkStandardNewMacro(vtkPenumbraShadowKeys);
vtkInformationKeyMacro(vtkPenumbraShadowKeys, OCCLUDER, Integer);
vtkInformationKeyMacro(vtkPenumbraShadowKeys, RECEIVER, Integer);
vtkInformationKeyMacro(vtkPenumbraShadowKeys, LIGHT_RADIUS, Double);

namespace
{
bool Flag(vtkProp* prop, vtkInformationIntegerKey* key)
{
  vtkInformation* info = prop ? prop->GetPropertyKeys() : nullptr;
  return !info || !info->Has(key) || info->Get(key) != 0;
}

void SetFlag(vtkProp* prop, vtkInformationIntegerKey* key, bool value)
{
  if (!prop)
  {
    return;
  }
  if (!prop->GetPropertyKeys())
  {
    vtkNew<vtkInformation> info;
    prop->SetPropertyKeys(info);
  }
  prop->GetPropertyKeys()->Set(key, value ? 1 : 0);
  prop->Modified();
}
}

bool vtkPenumbraShadowKeys::CastsShadows(vtkProp* prop)
{
  return Flag(prop, OCCLUDER());
}

bool vtkPenumbraShadowKeys::ReceivesShadows(vtkProp* prop)
{
  return Flag(prop, RECEIVER());
}

void vtkPenumbraShadowKeys::SetCastsShadows(vtkProp* prop, bool casts)
{
  SetFlag(prop, OCCLUDER(), casts);
}

void vtkPenumbraShadowKeys::SetReceivesShadows(vtkProp* prop, bool receives)
{
  SetFlag(prop, RECEIVER(), receives);
}

double vtkPenumbraShadowKeys::GetLightRadius(vtkLight* light)
{
  vtkInformation* info = light ? light->GetInformation() : nullptr;
  return info && info->Has(LIGHT_RADIUS()) ? info->Get(LIGHT_RADIUS()) : 0.0;
}

void vtkPenumbraShadowKeys::SetLightRadius(vtkLight* light, double radius)
{
  if (!light)
  {
    return;
  }
  if (!light->GetInformation())
  {
    vtkNew<vtkInformation> info;
    light->SetInformation(info);
  }
  if (radius == 0.0)
  {
    light->GetInformation()->Remove(LIGHT_RADIUS());
  }
  else
  {
    light->GetInformation()->Set(LIGHT_RADIUS(), radius);
  }
  light->Modified();
}
