/**
 * @class   vtkPVPenumbraShadowInformation
 * @brief   What a vtkPVPenumbraShadowView drew its last frame with, for the client.
 *
 * ParaView reads a proxy's information properties from the client's copy of the object
 * whenever the proxy exists there (vtkSMSessionClient::PullState), and a view exists on the
 * client and on the servers. With remote rendering it is the servers' views that draw and
 * gather the casters, so the client's copy knows nothing of it. This information object is
 * gathered from the first rank of the render server (vtkSMProxy::GatherInformation; root
 * only) and carries that view's statistics: the installed technique, the ShadowReport text and
 * the caster gather counters. vtkSMPenumbraShadowViewProxy copies them into the proxy's
 * information properties.
 */

#ifndef vtkPVPenumbraShadowInformation_h
#define vtkPVPenumbraShadowInformation_h

#include "vtkPVInformation.h"
#include "vtkPenumbraParaViewViewModule.h" // For export macro

#include <string> // For std::string

class VTKPENUMBRAPARAVIEWVIEW_EXPORT vtkPVPenumbraShadowInformation : public vtkPVInformation
{
public:
  static vtkPVPenumbraShadowInformation* New();
  vtkTypeMacro(vtkPVPenumbraShadowInformation, vtkPVInformation);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Reads a vtkPVPenumbraShadowView (anything else leaves the information empty).
   */
  void CopyFromObject(vtkObject* object) override;

  ///@{
  /**
   * Serialisation between the server and the client.
   */
  void CopyToStream(vtkClientServerStream* stream) override;
  void CopyFromStream(const vtkClientServerStream* stream) override;
  ///@}

  /**
   * Root only: nothing to merge; keeps `other`'s values if this one holds none.
   */
  void AddInformation(vtkPVInformation* other) override;

  ///@{
  /**
   * The view's values (see vtkPVPenumbraShadowView). Valid is false until CopyFromObject read
   * a shadow view.
   */
  bool GetValid() const { return this->Valid; }
  const char* GetInstalledTechnique() const { return this->InstalledTechnique.c_str(); }
  const char* GetShadowReport() const { return this->ShadowReport.c_str(); }
  double GetLastCasterGatherMs() const { return this->GatherMs; }
  vtkIdType GetNumberOfRemoteCasterTriangles() const { return this->RemoteTriangles; }
  vtkIdType GetCasterBytesReceived() const { return this->BytesReceived; }
  int GetNumberOfCasterGathers() const { return this->Gathers; }
  const char* GetCasterExchangeReport() const { return this->ExchangeReport.c_str(); }
  ///@}

protected:
  vtkPVPenumbraShadowInformation();
  ~vtkPVPenumbraShadowInformation() override;

private:
  vtkPVPenumbraShadowInformation(const vtkPVPenumbraShadowInformation&) = delete;
  void operator=(const vtkPVPenumbraShadowInformation&) = delete;

  bool Valid = false;
  std::string InstalledTechnique;
  std::string ShadowReport;
  double GatherMs = 0.0;
  vtkIdType RemoteTriangles = 0;
  vtkIdType BytesReceived = 0;
  int Gathers = 0;
  std::string ExchangeReport;
};

#endif
