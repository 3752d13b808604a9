// Writes the PenumbraShadowView proxy's XML: the template with one ParaView property per
// option of every technique of Penumbra's registry, generated from the option tables, so the
// properties panel and pvpython offer each option as a typed widget with its default, range
// or choices and doc, shown only while its technique is selected.
//
//   penumbra-paraview-options TEMPLATE.xml.in OUTPUT.xml
//
// The template's line holding PLACEHOLDER is replaced by the properties, the one holding
// GROUP_PLACEHOLDER by their names (the "Shadows" property group lists them). Each property
// calls the view's SetShadowOption<Type>("<technique>/<option>", value) through ParaView's
// `initial_string`.
#include "vtkPenumbraTechniques.h"

#include <cctype>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace
{
const char* const PLACEHOLDER = "<!-- @TECHNIQUE_OPTIONS@ -->";
const char* const GROUP_PLACEHOLDER = "<!-- @TECHNIQUE_OPTION_GROUP@ -->";

std::string Escape(const std::string& text)
{
  std::string out;
  for (char c : text)
  {
    switch (c)
    {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// "llsm-hybrid", "list_capacity" -> "Llsm Hybrid List Capacity": ParaView names a property's
// Python attribute after its label without spaces, so labels must differ across techniques.
std::string Label(const std::string& technique, const std::string& option)
{
  std::string label;
  bool wordStart = true;
  for (char c : technique + " " + option)
  {
    if (c == '-' || c == '_' || c == ' ')
    {
      label += ' ';
      wordStart = true;
      continue;
    }
    label += wordStart ? static_cast<char>(std::toupper(static_cast<unsigned char>(c))) : c;
    wordStart = false;
  }
  return label;
}

// A JSON string literal without its quotes (choices and defaults of choice options).
std::string Unquote(const std::string& json)
{
  return json.size() >= 2 && json.front() == '"' ? json.substr(1, json.size() - 2) : json;
}

// The property element's tag, setter and domain for option `index` of `technique`.
void WriteDomain(std::ostream& out, const char* technique, int index, const std::string& type)
{
  double bounds[2];
  const std::vector<std::string> choices =
    vtkPenumbraTechniques::GetOptionChoices(technique, index);
  if (type == "boolean")
  {
    out << "        <BooleanDomain name=\"bool\" />\n";
  }
  else if (vtkPenumbraTechniques::GetOptionBounds(technique, index, bounds))
  {
    std::ostringstream range;
    if (type == "integer")
    {
      range << "IntRangeDomain name=\"range\" min=\"" << static_cast<long long>(bounds[0])
            << "\" max=\"" << static_cast<long long>(bounds[1]) << "\"";
    }
    else
    {
      range << std::setprecision(17) << "DoubleRangeDomain name=\"range\" min=\"" << bounds[0]
            << "\" max=\"" << bounds[1] << "\"";
    }
    out << "        <" << range.str() << " />\n";
  }
  else if (type == "choice")
  {
    out << "        <StringListDomain name=\"list\">\n";
    for (const std::string& c : choices)
    {
      out << "          <String value=\"" << Escape(Unquote(c)) << "\" />\n";
    }
    out << "        </StringListDomain>\n";
  }
  else
  {
    out << "        <EnumerationDomain name=\"enum\">\n";
    for (const std::string& c : choices)
    {
      out << "          <Entry value=\"" << c << "\" text=\"" << c << "\" />\n";
    }
    out << "        </EnumerationDomain>\n";
  }
}

void WriteOption(std::ostream& out, const char* technique, int index)
{
  const std::string option = vtkPenumbraTechniques::GetOptionName(technique, index);
  const std::string type = vtkPenumbraTechniques::GetOptionType(technique, index);
  const std::string fallback = vtkPenumbraTechniques::GetOptionDefault(technique, index);
  std::string element = "IntVectorProperty", setter = "SetShadowOptionInteger";
  std::string value = fallback == "true" ? "1" : fallback == "false" ? "0" : fallback;
  if (type == "number")
  {
    element = "DoubleVectorProperty";
    setter = "SetShadowOptionNumber";
  }
  else if (type == "boolean")
  {
    setter = "SetShadowOptionBoolean";
  }
  else if (type == "choice")
  {
    element = "StringVectorProperty";
    setter = "SetShadowOptionChoice";
    value = Unquote(fallback);
  }
  const std::string unit = vtkPenumbraTechniques::GetOptionUnit(technique, index);
  out << "      <" << element << " name=\"" << technique << "/" << option << "\"\n"
      << "        label=\"" << Label(technique, option) << "\"\n"
      << "        command=\"" << setter << "\" initial_string=\"" << technique << "/" << option
      << "\"\n"
      << "        number_of_elements=\"1\" default_values=\"" << Escape(value) << "\">\n";
  WriteDomain(out, technique, index, type);
  out << "        <Documentation>" << Escape(vtkPenumbraTechniques::GetOptionDoc(technique, index))
      << (unit.empty() ? "" : " (" + Escape(unit) + ")") << "</Documentation>\n"
      << "        <Hints>\n"
      << "          <PropertyWidgetDecorator type=\"GenericDecorator\" mode=\"visibility\" "
      << "property=\"ShadowTechnique\" value=\"" << technique << "\" />\n"
      << "        </Hints>\n"
      << "      </" << element << ">\n";
}
}

int main(int argc, char* argv[])
{
  if (argc != 3)
  {
    std::cerr << "usage: " << argv[0] << " TEMPLATE.xml.in OUTPUT.xml\n";
    return 2;
  }
  std::ifstream in(argv[1]);
  if (!in)
  {
    std::cerr << argv[0] << ": cannot read " << argv[1] << "\n";
    return 1;
  }
  std::ostringstream generated, members;
  for (int t = 0; t < vtkPenumbraTechniques::GetNumberOfTechniques(); ++t)
  {
    const char* technique = vtkPenumbraTechniques::GetTechniqueName(t);
    for (int o = 0; o < vtkPenumbraTechniques::GetNumberOfOptions(technique); ++o)
    {
      WriteOption(generated, technique, o);
      members << "        <Property name=\"" << technique << "/"
              << vtkPenumbraTechniques::GetOptionName(technique, o) << "\" />\n";
    }
  }
  std::ostringstream text;
  std::string line;
  int replaced = 0;
  while (std::getline(in, line))
  {
    if (line.find(PLACEHOLDER) != std::string::npos)
    {
      text << generated.str();
      replaced |= 1;
    }
    else if (line.find(GROUP_PLACEHOLDER) != std::string::npos)
    {
      text << members.str();
      replaced |= 2;
    }
    else
    {
      text << line << "\n";
    }
  }
  if (replaced != 3)
  {
    std::cerr << argv[0] << ": " << argv[1] << " needs a " << PLACEHOLDER << " line and a "
              << GROUP_PLACEHOLDER << " line\n";
    return 1;
  }
  std::ofstream out(argv[2]);
  out << text.str();
  return out ? 0 : 1;
}
