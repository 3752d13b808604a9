// The option tables' machinery: validation and typed reads (see vtkPenumbraTechniqueOptions.h).
#include "vtkPenumbraTechniqueOptions.h"

#include <algorithm>
#include <cstring>

namespace penumbra_options
{
namespace
{
std::string JoinValues(const std::vector<json>& values)
{
  std::string text;
  for (const auto& v : values)
  {
    text += (text.empty() ? "" : ", ") + v.dump();
  }
  return text;
}

void Check(const OptionSpec& spec, const json& v)
{
  const std::string key = spec.Name;
  switch (spec.Type)
  {
    case OptionType::Integer:
      if (!v.is_number_integer() || v.get<long long>() < spec.Min || v.get<long long>() > spec.Max)
      {
        throw OptionError(key + ": expected an integer in [" +
          json(static_cast<long long>(spec.Min)).dump() + ", " +
          json(static_cast<long long>(spec.Max)).dump() + "], got " + v.dump());
      }
      if (!spec.Values.empty() &&
        std::find(spec.Values.begin(), spec.Values.end(), v) == spec.Values.end())
      {
        throw OptionError(
          key + ": expected one of " + JoinValues(spec.Values) + ", got " + v.dump());
      }
      return;
    case OptionType::Number:
      if (!v.is_number() || !(v.get<double>() >= spec.Min) || !(v.get<double>() <= spec.Max))
      {
        throw OptionError(key + ": expected a number in [" + json(spec.Min).dump() + ", " +
          json(spec.Max).dump() + "], got " + v.dump());
      }
      return;
    case OptionType::Boolean:
      if (!v.is_boolean())
      {
        throw OptionError(key + ": expected true or false, got " + v.dump());
      }
      return;
    case OptionType::Choice:
      if (std::find(spec.Values.begin(), spec.Values.end(), v) == spec.Values.end())
      {
        throw OptionError(
          key + ": expected one of " + JoinValues(spec.Values) + ", got " + v.dump());
      }
      return;
  }
}

}

const char* TypeName(OptionType type)
{
  switch (type)
  {
    case OptionType::Integer:
      return "integer";
    case OptionType::Number:
      return "number";
    case OptionType::Boolean:
      return "boolean";
    case OptionType::Choice:
      return "choice";
  }
  return "";
}

std::string RangeText(const OptionSpec& spec)
{
  switch (spec.Type)
  {
    case OptionType::Integer:
      return spec.Values.empty() ? json(static_cast<long long>(spec.Min)).dump() + ".." +
          json(static_cast<long long>(spec.Max)).dump()
                                 : JoinValues(spec.Values);
    case OptionType::Number:
      return json(spec.Min).dump() + ".." + json(spec.Max).dump();
    case OptionType::Boolean:
      return "true, false";
    case OptionType::Choice:
      return JoinValues(spec.Values);
  }
  return "";
}

Options::Options(const json& j, const OptionTable& table)
  : J(j)
  , Table(table)
{
  for (const auto& spec : table)
  {
    if (j.contains(spec.Name))
    {
      Check(spec, j.at(spec.Name));
    }
  }
  this->RejectUnknown();
}

int Options::Integer(const char* key) const
{
  return static_cast<int>(this->Value(key).get<long long>());
}

double Options::Number(const char* key) const
{
  return this->Value(key).get<double>();
}

bool Options::Boolean(const char* key) const
{
  return this->Value(key).get<bool>();
}

int Options::Choice(const char* key) const
{
  const json& v = this->Value(key);
  const auto& values = this->Spec(key).Values;
  return static_cast<int>(std::find(values.begin(), values.end(), v) - values.begin());
}

void Options::RejectUnknown() const
{
  for (auto it = this->J.begin(); it != this->J.end(); ++it)
  {
    const bool known = std::any_of(this->Table.begin(), this->Table.end(),
      [&](const OptionSpec& spec) { return it.key() == spec.Name; });
    if (!known)
    {
      std::string allowed;
      for (const auto& spec : this->Table)
      {
        allowed += (allowed.empty() ? "" : ", ") + std::string(spec.Name);
      }
      throw OptionError(it.key() + ": unknown option" +
        (allowed.empty() ? std::string(" (this technique has none)")
                         : " (allowed: " + allowed + ")"));
    }
  }
}

const OptionSpec& Options::Spec(const char* key) const
{
  for (const auto& spec : this->Table)
  {
    if (std::strcmp(spec.Name, key) == 0)
    {
      return spec;
    }
  }
  throw std::logic_error(std::string("option not in the technique's table: ") + key);
}

const json& Options::Value(const char* key) const
{
  const OptionSpec& spec = this->Spec(key);
  return this->J.contains(key) ? this->J.at(key) : spec.Default;
}

const OptionSpec& SamplesOption()
{
  static const OptionSpec spec = { "samples", OptionType::Integer, 0, 0, 32, { 0, 4, 8, 16, 32 },
    "samples per axis",
    "light samples per axis of area and linear lights (k x k, at the light's cell centres); 0 "
    "keeps the light's own `samples`" };
  return spec;
}
}
