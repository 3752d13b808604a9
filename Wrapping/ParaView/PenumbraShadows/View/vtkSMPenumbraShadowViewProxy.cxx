#include "vtkSMPenumbraShadowViewProxy.h"

#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPVPenumbraShadowInformation.h"
#include "vtkPVPenumbraShadowView.h"
#include "vtkPVSession.h"
#include "vtkPVXMLElement.h"
#include "vtkSMProperty.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSmartPointer.h"

#include <nlohmann/json.hpp>

#include <cstring>
#include <set>
#include <string>
#include <vector>

namespace
{
// The information properties that describe the last frame, and so must come from the
// process that drew it.
const char* const StatisticsProperties[] = { "InstalledShadowTechnique", "ShadowReport",
  "CasterGathers", "CasterGatherMs", "RemoteCasterTriangles", "CasterBytesReceived",
  "CasterExchangeReport" };

// The names of the properties the group labelled `label` lists, and whether it exists.
bool GroupMembers(vtkPVXMLElement* element, const char* label, std::set<std::string>& names)
{
  bool found = false;
  for (unsigned int i = 0; i < element->GetNumberOfNestedElements(); ++i)
  {
    vtkPVXMLElement* child = element->GetNestedElement(i);
    const char* childLabel = child->GetAttribute("label");
    if (std::strcmp(child->GetName(), "PropertyGroup") != 0 || !childLabel ||
      std::strcmp(childLabel, label) != 0)
    {
      continue;
    }
    found = true;
    for (unsigned int k = 0; k < child->GetNumberOfNestedElements(); ++k)
    {
      vtkPVXMLElement* member = child->GetNestedElement(k);
      if (std::strcmp(member->GetName(), "Property") == 0 && member->GetAttribute("name"))
      {
        names.insert(member->GetAttribute("name"));
      }
    }
  }
  return found;
}

// Sets `prop` from a JSON option value (booleans as 0/1, as the option properties take them).
void SetFromJson(vtkSMProperty* prop, const nlohmann::json& value)
{
  vtkSMPropertyHelper helper(prop);
  if (value.is_boolean())
  {
    helper.Set(value.get<bool>() ? 1 : 0);
  }
  else if (value.is_number_integer())
  {
    helper.Set(value.get<int>());
  }
  else if (value.is_number())
  {
    helper.Set(value.get<double>());
  }
  else if (value.is_string())
  {
    helper.Set(value.get<std::string>().c_str());
  }
}
}

vtkStandardNewMacro(vtkSMPenumbraShadowViewProxy);

vtkSMPenumbraShadowViewProxy::vtkSMPenumbraShadowViewProxy() = default;

vtkSMPenumbraShadowViewProxy::~vtkSMPenumbraShadowViewProxy() = default;

int vtkSMPenumbraShadowViewProxy::ReadXMLAttributes(
  vtkSMSessionProxyManager* pm, vtkPVXMLElement* element)
{
  std::set<std::string> grouped;
  if (!element || !GroupMembers(element, GetShadowsGroupLabel(), grouped))
  {
    return this->Superclass::ReadXMLAttributes(pm, element);
  }
  // The proxy's property order is its definition's element order (the panel follows it), and
  // the definition manager shares the flattened definition: reorder a copy.
  vtkNew<vtkPVXMLElement> ordered;
  element->CopyAttributesTo(ordered);
  std::vector<vtkSmartPointer<vtkPVXMLElement>> first, rest;
  for (unsigned int i = 0; i < element->GetNumberOfNestedElements(); ++i)
  {
    vtkPVXMLElement* child = element->GetNestedElement(i);
    auto copy = vtkSmartPointer<vtkPVXMLElement>::New();
    child->CopyTo(copy);
    const char* name = child->GetAttribute("name");
    (name && grouped.count(name) ? first : rest).push_back(copy);
  }
  for (const auto& list : { first, rest })
  {
    for (const auto& child : list)
    {
      ordered->AddNestedElement(child);
    }
  }
  return this->Superclass::ReadXMLAttributes(pm, ordered);
}

void vtkSMPenumbraShadowViewProxy::UpdatePropertyInformationInternal(vtkSMProperty* prop)
{
  this->Superclass::UpdatePropertyInformationInternal(prop);
  this->UpdateStatisticsFromRenderServer(prop);
}

void vtkSMPenumbraShadowViewProxy::UpdateStatisticsFromRenderServer(vtkSMProperty* prop)
{
  bool wanted = prop == nullptr;
  for (const char* name : StatisticsProperties)
  {
    wanted = wanted || prop == this->GetProperty(name);
  }
  // Without remote rendering the client's view drew the frame: what was pulled is right.
  auto* view = vtkPVPenumbraShadowView::SafeDownCast(this->GetClientSideObject());
  if (!wanted || !view || (view->GetStillRenderProcesses() & vtkPVSession::RENDER_SERVER) == 0)
  {
    return;
  }
  // Whether it worked is Valid: vtkSMSessionClient::GatherInformation returns false even when
  // the server answered (ParaView 5.11).
  vtkNew<vtkPVPenumbraShadowInformation> info;
  this->GatherInformation(info, vtkPVSession::RENDER_SERVER);
  if (!info->GetValid())
  {
    return;
  }
  vtkSMPropertyHelper(this, "InstalledShadowTechnique").Set(info->GetInstalledTechnique());
  vtkSMPropertyHelper(this, "ShadowReport").Set(info->GetShadowReport());
  vtkSMPropertyHelper(this, "CasterGathers").Set(info->GetNumberOfCasterGathers());
  vtkSMPropertyHelper(this, "CasterGatherMs").Set(info->GetLastCasterGatherMs());
  vtkSMPropertyHelper(this, "RemoteCasterTriangles").Set(info->GetNumberOfRemoteCasterTriangles());
  vtkSMPropertyHelper(this, "CasterBytesReceived").Set(info->GetCasterBytesReceived());
  vtkSMPropertyHelper(this, "CasterExchangeReport").Set(info->GetCasterExchangeReport());
}

void vtkSMPenumbraShadowViewProxy::PostRender(bool interactive)
{
  this->Superclass::PostRender(interactive);
  this->RestoreRefusedRequest();
}

bool vtkSMPenumbraShadowViewProxy::RestoreRefusedRequest()
{
  auto* view = vtkPVPenumbraShadowView::SafeDownCast(this->GetClientSideObject());
  if (!view || !view->GetShadowRequestRefused() || !*view->GetInstalledTechnique())
  {
    return false;
  }
  const std::string technique = view->GetInstalledTechnique();
  vtkSMPropertyHelper(this, "ShadowTechnique").Set(technique.c_str());
  vtkSMPropertyHelper(this, "ShadowOptions").Set(view->GetInstalledShadowOptions());
  const nlohmann::json values =
    nlohmann::json::parse(view->GetInstalledOptionValues(), nullptr, false);
  if (values.is_object())
  {
    for (const auto& item : values.items())
    {
      if (vtkSMProperty* prop = this->GetProperty((technique + "/" + item.key()).c_str()))
      {
        SetFromJson(prop, item.value());
      }
    }
  }
  this->UpdateVTKObjects();
  return true;
}

void vtkSMPenumbraShadowViewProxy::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
