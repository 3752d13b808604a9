#include "vtkPVPenumbraShadowInformation.h"

#include "vtkClientServerStream.h"
#include "vtkObjectFactory.h"
#include "vtkPVPenumbraShadowView.h"

vtkStandardNewMacro(vtkPVPenumbraShadowInformation);

vtkPVPenumbraShadowInformation::vtkPVPenumbraShadowInformation()
{
  // The properties describe the first rank; the other ranks need not take part.
  this->RootOnly = 1;
}

vtkPVPenumbraShadowInformation::~vtkPVPenumbraShadowInformation() = default;

void vtkPVPenumbraShadowInformation::CopyFromObject(vtkObject* object)
{
  auto* view = vtkPVPenumbraShadowView::SafeDownCast(object);
  this->Valid = view != nullptr;
  if (!view)
  {
    return;
  }
  this->InstalledTechnique = view->GetInstalledTechnique();
  this->ShadowReport = view->GetShadowReport();
  this->GatherMs = view->GetLastCasterGatherMs();
  this->RemoteTriangles = view->GetNumberOfRemoteCasterTriangles();
  this->BytesReceived = view->GetCasterBytesReceived();
  this->Gathers = view->GetNumberOfCasterGathers();
  this->ExchangeReport = view->GetCasterExchangeReport();
}

void vtkPVPenumbraShadowInformation::CopyToStream(vtkClientServerStream* stream)
{
  stream->Reset();
  *stream << vtkClientServerStream::Reply << (this->Valid ? 1 : 0)
          << this->InstalledTechnique.c_str() << this->ShadowReport.c_str() << this->GatherMs
          << this->RemoteTriangles << this->BytesReceived << this->Gathers
          << this->ExchangeReport.c_str() << vtkClientServerStream::End;
}

void vtkPVPenumbraShadowInformation::CopyFromStream(const vtkClientServerStream* stream)
{
  int valid = 0;
  const char* technique = nullptr;
  const char* report = nullptr;
  const char* exchange = nullptr;
  this->Valid = stream->GetArgument(0, 0, &valid) && valid != 0 &&
    stream->GetArgument(0, 1, &technique) && stream->GetArgument(0, 2, &report) &&
    stream->GetArgument(0, 3, &this->GatherMs) &&
    stream->GetArgument(0, 4, &this->RemoteTriangles) &&
    stream->GetArgument(0, 5, &this->BytesReceived) && stream->GetArgument(0, 6, &this->Gathers) &&
    stream->GetArgument(0, 7, &exchange);
  this->InstalledTechnique = technique ? technique : "";
  this->ShadowReport = report ? report : "";
  this->ExchangeReport = exchange ? exchange : "";
}

void vtkPVPenumbraShadowInformation::AddInformation(vtkPVInformation* other)
{
  auto* info = vtkPVPenumbraShadowInformation::SafeDownCast(other);
  if (info && info->Valid && !this->Valid)
  {
    this->Valid = true;
    this->InstalledTechnique = info->InstalledTechnique;
    this->ShadowReport = info->ShadowReport;
    this->GatherMs = info->GatherMs;
    this->RemoteTriangles = info->RemoteTriangles;
    this->BytesReceived = info->BytesReceived;
    this->Gathers = info->Gathers;
    this->ExchangeReport = info->ExchangeReport;
  }
}

void vtkPVPenumbraShadowInformation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Valid: " << (this->Valid ? "yes" : "no") << "\n";
  os << indent << "InstalledTechnique: " << this->InstalledTechnique << "\n";
  os << indent << "CasterGathers: " << this->Gathers << "\n";
  os << indent << "CasterGatherMs: " << this->GatherMs << "\n";
  os << indent << "RemoteCasterTriangles: " << this->RemoteTriangles << "\n";
  os << indent << "CasterBytesReceived: " << this->BytesReceived << "\n";
}
