#include "vtkPenumbraStatistics.h"

#include "vtkObjectFactory.h"

#include <cmath>
#include <limits>
#include <sstream>

vtkStandardNewMacro(vtkPenumbraStatistics);

void vtkPenumbraStatistics::Clear()
{
  this->Entries.clear();
}

vtkPenumbraStatistics::Entry* vtkPenumbraStatistics::Find(const char* name)
{
  const std::string key = name ? name : "";
  for (Entry& e : this->Entries)
  {
    if (e.Name == key)
    {
      return &e;
    }
  }
  return nullptr;
}

void vtkPenumbraStatistics::Set(const char* name, double value)
{
  if (Entry* e = this->Find(name))
  {
    e->Value = value;
    return;
  }
  this->Entries.push_back({ name ? name : "", value });
}

int vtkPenumbraStatistics::GetNumberOfEntries()
{
  return static_cast<int>(this->Entries.size());
}

const char* vtkPenumbraStatistics::GetName(int index)
{
  return index >= 0 && index < this->GetNumberOfEntries()
    ? this->Entries[static_cast<size_t>(index)].Name.c_str()
    : "";
}

double vtkPenumbraStatistics::GetValue(int index)
{
  return index >= 0 && index < this->GetNumberOfEntries()
    ? this->Entries[static_cast<size_t>(index)].Value
    : std::numeric_limits<double>::quiet_NaN();
}

bool vtkPenumbraStatistics::Has(const char* name)
{
  return this->Find(name) != nullptr;
}

double vtkPenumbraStatistics::Get(const char* name)
{
  const Entry* e = this->Find(name);
  return e ? e->Value : std::numeric_limits<double>::quiet_NaN();
}

std::string vtkPenumbraStatistics::Format(const char* separator)
{
  std::ostringstream out;
  for (size_t i = 0; i < this->Entries.size(); ++i)
  {
    const double v = this->Entries[i].Value;
    out << (i ? separator : "") << this->Entries[i].Name << " ";
    if (std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 1e15)
    {
      out << static_cast<long long>(v);
    }
    else
    {
      out.precision(4);
      out << v;
    }
  }
  return out.str();
}

void vtkPenumbraStatistics::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  for (const Entry& e : this->Entries)
  {
    os << indent << e.Name << ": " << e.Value << "\n";
  }
}
