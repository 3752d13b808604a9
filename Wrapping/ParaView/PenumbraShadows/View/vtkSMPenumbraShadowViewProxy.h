/**
 * @class   vtkSMPenumbraShadowViewProxy
 * @brief   Server-manager proxy of vtkPVPenumbraShadowView (XML tag PenumbraShadowViewProxy).
 *
 * A vtkSMRenderViewProxy with three additions, all on the client side:
 *
 * - **Statistics from where the view drew.** After the information properties are pulled
 *   (from the client's copy of the view, as for any proxy), when the last still render ran on
 *   the render server (remote rendering in client/server mode) the statistics properties
 *   (InstalledShadowTechnique, ShadowReport, CasterGathers, CasterGatherMs,
 *   RemoteCasterTriangles, CasterBytesReceived) are replaced by the render server's first
 *   rank's values, gathered as a vtkPVPenumbraShadowInformation.
 * - **A refused request is undone.** After each render, when the view refused the requested
 *   technique or options (vtkPVPenumbraShadowView::GetShadowRequestRefused(); the client's view
 *   tries the same request with the same registry as the servers'), ShadowTechnique,
 *   ShadowOptions and the installed technique's option properties are set back to what the
 *   view draws with and pushed, so pvpython and the Properties panel show the technique that
 *   draws. Nothing is undone before a first technique was installed.
 * - **The Shadows group first.** The properties of the "Shadows" property group are moved to
 *   the front of the proxy's property order, which the Properties panel follows, so the group
 *   is at the top of the view's section instead of below all of the render view's properties
 *   (an inherited definition puts the base proxy's properties first).
 */

#ifndef vtkSMPenumbraShadowViewProxy_h
#define vtkSMPenumbraShadowViewProxy_h

#include "vtkPenumbraParaViewViewModule.h" // For export macro
#include "vtkSMRenderViewProxy.h"

class VTKPENUMBRAPARAVIEWVIEW_EXPORT vtkSMPenumbraShadowViewProxy : public vtkSMRenderViewProxy
{
public:
  static vtkSMPenumbraShadowViewProxy* New();
  vtkTypeMacro(vtkSMPenumbraShadowViewProxy, vtkSMRenderViewProxy);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * The label of the property group moved to the front of the property order.
   */
  static const char* GetShadowsGroupLabel() { return "Shadows"; }

protected:
  vtkSMPenumbraShadowViewProxy();
  ~vtkSMPenumbraShadowViewProxy() override;

  int ReadXMLAttributes(vtkSMSessionProxyManager* pm, vtkPVXMLElement* element) override;
  void UpdatePropertyInformationInternal(vtkSMProperty* prop = nullptr) override;
  void PostRender(bool interactive) override;

private:
  vtkSMPenumbraShadowViewProxy(const vtkSMPenumbraShadowViewProxy&) = delete;
  void operator=(const vtkSMPenumbraShadowViewProxy&) = delete;

  // Sets the request properties back to what the client's view draws with, if it refused
  // the last request. True when something was pushed.
  bool RestoreRefusedRequest();
  // The statistics of the render server's first rank, when it drew the last frame.
  void UpdateStatisticsFromRenderServer(vtkSMProperty* prop);
};

#endif
