// vtkPenumbraMeshFileCheck: the PLY check (Greg Turk's format as VTK's vtkPLY reads it), header
// and body, ASCII and binary.

#include "vtkPenumbraMeshFileCheckInternals.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

using namespace penumbra_mesh_check;

namespace
{
// VTK's vtkPLY reads ASCII lines (header and records) into a 4096-byte buffer with fgets and
// overwrites its last two bytes: a longer line is silently split into two records.
constexpr size_t PlyMaxLine = 4094;

// More properties per element than any mesh has; keeps count x record size inside 64 bits.
constexpr size_t PlyMaxProperties = 4096;

//------------------------------------------------------------------------------------------
// PLY header (Greg Turk's format as read by VTK's vtkPLY)

struct PlyProperty
{
  std::string Name;
  bool IsList = false;
  int CountSize = 0; // bytes of a list's length
  bool CountSigned = false;
  bool CountFloat = false;
  int Size = 0; // bytes of the value or of each list item
  bool Float = false;
  bool Signed = false;
};

struct PlyElement
{
  std::string Name;
  long long Count = 0;
  std::vector<PlyProperty> Properties;
};

enum class PlyFormat
{
  Ascii,
  BinaryLittleEndian,
  BinaryBigEndian
};

struct PlyHeader
{
  PlyFormat Format = PlyFormat::Ascii;
  std::vector<PlyElement> Elements;
  std::streamoff DataOffset = 0; // first byte after "end_header\n"
};

// Size, signedness and kind of a PLY scalar type name; false for an unknown name.
bool PlyType(const std::string& name, int& size, bool& isSigned, bool& isFloat)
{
  struct Entry
  {
    const char* Name;
    int Size;
    bool Signed;
    bool Float;
  };
  static const Entry types[] = { { "char", 1, true, false }, { "int8", 1, true, false },
    { "uchar", 1, false, false }, { "uint8", 1, false, false }, { "short", 2, true, false },
    { "int16", 2, true, false }, { "ushort", 2, false, false }, { "uint16", 2, false, false },
    { "int", 4, true, false }, { "int32", 4, true, false }, { "uint", 4, false, false },
    { "uint32", 4, false, false }, { "float", 4, true, true }, { "float32", 4, true, true },
    { "double", 8, true, true }, { "float64", 8, true, true } };
  for (const auto& t : types)
  {
    if (name == t.Name)
    {
      size = t.Size;
      isSigned = t.Signed;
      isFloat = t.Float;
      return true;
    }
  }
  return false;
}

// Reads one header line (without its end of line); false at the end of the file.
bool HeaderLine(std::istream& in, std::string& line, int number)
{
  line.clear();
  char c;
  while (in.get(c))
  {
    if (c == '\n')
    {
      break;
    }
    line.push_back(c);
    if (line.size() > PlyMaxLine)
    {
      Fail("PLY header line " + std::to_string(number) + " is longer than " +
        std::to_string(PlyMaxLine) + " characters");
    }
  }
  if (!in && line.empty())
  {
    return false;
  }
  if (!line.empty() && line.back() == '\r')
  {
    line.pop_back();
  }
  return true;
}

long long ParseCount(const std::string& word, const std::string& element)
{
  errno = 0;
  char* end = nullptr;
  const long long n = std::strtoll(word.c_str(), &end, 10);
  if (word.empty() || *end != '\0' || errno == ERANGE)
  {
    Fail("PLY element \"" + element + "\" has the count \"" + word + "\", not an integer");
  }
  if (n < 0 || n > PlyMaxCount)
  {
    Fail("PLY element \"" + element + "\" has the count " + word + " (allowed: 0 to " +
      std::to_string(PlyMaxCount) + ")");
  }
  return n;
}

PlyProperty ParseProperty(const std::vector<std::string>& w, const PlyElement& element)
{
  PlyProperty p;
  const bool list = w.size() >= 2 && w[1] == "list";
  if ((list && w.size() != 5) || (!list && w.size() != 3))
  {
    Fail("PLY header: malformed property line in element \"" + element.Name +
      "\" (expected \"property TYPE NAME\" or \"property list COUNT_TYPE ITEM_TYPE NAME\")");
  }
  const std::string& type = list ? w[3] : w[1];
  p.IsList = list;
  p.Name = w.back();
  if (!PlyType(type, p.Size, p.Signed, p.Float))
  {
    Fail(
      "PLY property \"" + element.Name + "." + p.Name + "\" has the unknown type \"" + type + "\"");
  }
  if (list)
  {
    bool isSigned = false, isFloat = false;
    if (!PlyType(w[2], p.CountSize, isSigned, isFloat) || isFloat)
    {
      Fail("PLY list \"" + element.Name + "." + p.Name + "\" has the count type \"" + w[2] +
        "\" (expected an integer type)");
    }
    p.CountSigned = isSigned;
  }
  return p;
}

PlyHeader ReadPlyHeader(std::istream& in)
{
  PlyHeader header;
  std::string line;
  int number = 1;
  if (!HeaderLine(in, line, number) || line != "ply")
  {
    Fail("not a PLY file (the first line must be \"ply\")");
  }
  bool haveFormat = false;
  while (true)
  {
    ++number;
    if (!HeaderLine(in, line, number))
    {
      Fail("PLY header has no \"end_header\" line");
    }
    const auto w = Words(line);
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info")
    {
      continue;
    }
    if (w[0] == "end_header")
    {
      break;
    }
    if (w[0] == "format")
    {
      if (w.size() != 3 ||
        (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
      {
        Fail("PLY header: unknown format line \"" + line + "\"");
      }
      header.Format = w[1] == "ascii"    ? PlyFormat::Ascii
        : w[1] == "binary_little_endian" ? PlyFormat::BinaryLittleEndian
                                         : PlyFormat::BinaryBigEndian;
      haveFormat = true;
    }
    else if (w[0] == "element")
    {
      if (w.size() != 3)
      {
        Fail(
          "PLY header: malformed element line \"" + line + "\" (expected \"element NAME COUNT\")");
      }
      PlyElement e;
      e.Name = w[1];
      e.Count = ParseCount(w[2], e.Name);
      header.Elements.push_back(e);
    }
    else if (w[0] == "property")
    {
      if (header.Elements.empty())
      {
        Fail("PLY header: a property comes before any element");
      }
      PlyElement& e = header.Elements.back();
      if (e.Properties.size() >= PlyMaxProperties)
      {
        Fail("PLY element \"" + e.Name + "\" has more than " + std::to_string(PlyMaxProperties) +
          " properties");
      }
      e.Properties.push_back(ParseProperty(w, e));
    }
    else
    {
      Fail("PLY header line " + std::to_string(number) + " starts with the unknown keyword \"" +
        w[0] + "\"");
    }
  }
  if (!haveFormat)
  {
    Fail("PLY header has no format line");
  }
  header.DataOffset = in.tellg();
  return header;
}

// The vertex element with x, y and z: what VTK's PLY reader needs to make points.
const PlyElement* VertexElement(const PlyHeader& header)
{
  for (const auto& e : header.Elements)
  {
    if (e.Name == "vertex")
    {
      int xyz = 0;
      for (const auto& p : e.Properties)
      {
        xyz += (!p.IsList && (p.Name == "x" || p.Name == "y" || p.Name == "z")) ? 1 : 0;
      }
      if (xyz != 3)
      {
        Fail("PLY element \"vertex\" needs the scalar properties x, y and z");
      }
      return &e;
    }
  }
  Fail("PLY file has no \"vertex\" element");
}

bool IsFaceIndexList(const PlyElement& e, const PlyProperty& p)
{
  // vtkPLY reads "vertex_index" as "vertex_indices".
  return p.IsList && e.Name == "face" && (p.Name == "vertex_indices" || p.Name == "vertex_index");
}

// VTK's PLY reader reads a "face" element's vertex_indices without asking whether the file
// has them, and crashes on a face element without that list.
void CheckFaceElement(const PlyHeader& header)
{
  for (const auto& e : header.Elements)
  {
    if (e.Name != "face")
    {
      continue;
    }
    int lists = 0;
    for (const auto& p : e.Properties)
    {
      lists += IsFaceIndexList(e, p) ? 1 : 0;
    }
    if (lists != 1)
    {
      Fail("PLY element \"face\" needs exactly one list property \"vertex_indices\"");
    }
  }
}

//------------------------------------------------------------------------------------------
// PLY body

// What every record check needs: the vertex count for face indices, and where we are.
struct PlyWalk
{
  long long Vertices = 0;
  const PlyElement* Element = nullptr;
  long long Record = 0;

  std::string Where() const
  {
    return "\"" + this->Element->Name + "\" record " + std::to_string(this->Record + 1) + " of " +
      std::to_string(this->Element->Count);
  }

  void CheckListLength(double n, const PlyProperty& p) const
  {
    if (n < 0 || n != std::floor(n))
    {
      std::ostringstream msg;
      msg << "PLY " << this->Where() << ": list \"" << p.Name << "\" has the length " << n
          << " (expected a whole number, at least 0)";
      Fail(msg.str());
    }
    if (IsFaceIndexList(*this->Element, p) && n < 3)
    {
      Fail("PLY " + this->Where() + ": a face needs at least 3 vertices, this one has " +
        std::to_string(static_cast<long long>(n)));
    }
  }

  void CheckItem(double v, const PlyProperty& p) const
  {
    if (IsFaceIndexList(*this->Element, p) &&
      !(v >= 0 && v < static_cast<double>(this->Vertices) && v == std::floor(v)))
    {
      std::ostringstream msg;
      msg << "PLY " << this->Where() << ": vertex index " << v << " is outside the "
          << this->Vertices << " vertices";
      Fail(msg.str());
    }
  }
};

class BinaryBody
{
public:
  BinaryBody(std::istream& in, std::streamoff begin, std::streamoff end, bool bigEndian)
    : In(in)
    , Left(end - begin)
    , BigEndian(bigEndian)
  {
    in.clear();
    in.seekg(begin);
  }

  // Skips `bytes` (a whole fixed-size element); false if the file is shorter.
  bool Skip(long long bytes)
  {
    if (bytes > this->Left)
    {
      return false;
    }
    this->In.seekg(bytes, std::ios::cur);
    this->Left -= bytes;
    return true;
  }

  bool Read(int size, bool isSigned, bool isFloat, double& value)
  {
    unsigned char b[8];
    if (size > this->Left || !this->In.read(reinterpret_cast<char*>(b), size))
    {
      return false;
    }
    this->Left -= size;
    value = DecodeBinary(b, size, isSigned, isFloat, this->BigEndian);
    return true;
  }

  long long Remaining() const { return this->Left; }

private:
  std::istream& In;
  long long Left;
  bool BigEndian;
};

void CheckBinaryElement(BinaryBody& body, PlyWalk& walk, const PlyElement& e)
{
  long long recordSize = 0;
  bool fixed = true;
  bool indices = false;
  for (const auto& p : e.Properties)
  {
    fixed = fixed && !p.IsList;
    indices = indices || IsFaceIndexList(e, p);
    recordSize += p.Size;
  }
  walk.Element = &e;
  if (fixed)
  {
    // Compared by division: a hostile count times a record size can overflow.
    if ((recordSize > 0 && e.Count > body.Remaining() / recordSize) ||
      !body.Skip(e.Count * recordSize))
    {
      Fail("binary PLY ends inside element \"" + e.Name + "\": the header promises " +
        std::to_string(e.Count) + " records of " + std::to_string(recordSize) + " bytes (" +
        std::to_string(e.Count * recordSize) + " bytes), only " + std::to_string(body.Remaining()) +
        " bytes are left");
    }
    return;
  }
  for (walk.Record = 0; walk.Record < e.Count; ++walk.Record)
  {
    for (const auto& p : e.Properties)
    {
      double v = 0;
      const auto truncated = [&]
      {
        Fail("binary PLY ends inside " + walk.Where() + " (the header promises " +
          std::to_string(e.Count) + " records)");
      };
      if (!p.IsList)
      {
        if (!body.Read(p.Size, p.Signed, p.Float, v))
        {
          truncated();
        }
        continue;
      }
      double n = 0;
      if (!body.Read(p.CountSize, p.CountSigned, false, n))
      {
        truncated();
      }
      walk.CheckListLength(n, p);
      const long long count = static_cast<long long>(n);
      if (count * p.Size > body.Remaining())
      {
        Fail("binary PLY ends inside " + walk.Where() + ": list \"" + p.Name + "\" of " +
          std::to_string(count) + " items runs past the end of the file");
      }
      for (long long k = 0; k < count; ++k)
      {
        body.Read(p.Size, p.Signed, p.Float, v);
        if (indices)
        {
          walk.CheckItem(v, p);
        }
      }
    }
  }
}

// One ASCII record per line, as vtkPLY reads them.
class AsciiBody
{
public:
  AsciiBody(std::istream& in, std::streamoff begin)
    : In(in)
  {
    in.clear();
    in.seekg(begin);
  }

  bool NextLine(std::vector<std::string>& words)
  {
    std::string line;
    if (!std::getline(this->In, line))
    {
      return false;
    }
    ++this->Line;
    if (line.size() > PlyMaxLine)
    {
      Fail("ASCII PLY data line " + std::to_string(this->Line) + " is longer than " +
        std::to_string(PlyMaxLine) + " characters, which VTK's PLY reader splits");
    }
    words = Words(line);
    return true;
  }

private:
  std::istream& In;
  long long Line = 0;
};

double AsciiValue(
  const PlyWalk& walk, const std::vector<std::string>& words, size_t& next, const PlyProperty& p)
{
  if (next >= words.size())
  {
    Fail("ASCII PLY " + walk.Where() + " has too few values on its line (\"" + p.Name +
      "\" is missing)");
  }
  const std::string& word = words[next++];
  char* end = nullptr;
  const double v = std::strtod(word.c_str(), &end);
  if (*end != '\0')
  {
    Fail("ASCII PLY " + walk.Where() + ": \"" + word + "\" is not a number");
  }
  return v;
}

void CheckAsciiElement(AsciiBody& body, PlyWalk& walk, const PlyElement& e)
{
  walk.Element = &e;
  std::vector<std::string> words;
  for (walk.Record = 0; walk.Record < e.Count; ++walk.Record)
  {
    if (!body.NextLine(words))
    {
      Fail("ASCII PLY ends before " + walk.Where());
    }
    if (words.empty())
    {
      Fail("ASCII PLY " + walk.Where() + " is an empty line");
    }
    size_t next = 0;
    for (const auto& p : e.Properties)
    {
      const double first = AsciiValue(walk, words, next, p);
      if (!p.IsList)
      {
        continue;
      }
      walk.CheckListLength(first, p);
      if (first > static_cast<double>(words.size() - next))
      {
        Fail("ASCII PLY " + walk.Where() + ": list \"" + p.Name + "\" promises " +
          std::to_string(static_cast<long long>(first)) + " items, the line has fewer");
      }
      for (long long k = 0; k < static_cast<long long>(first); ++k)
      {
        walk.CheckItem(AsciiValue(walk, words, next, p), p);
      }
    }
  }
}
}

namespace penumbra_mesh_check
{
std::vector<std::string> Words(const std::string& line)
{
  std::vector<std::string> words;
  std::istringstream in(line);
  std::string w;
  while (in >> w)
  {
    words.push_back(w);
  }
  return words;
}

double DecodeBinary(const unsigned char* b, int size, bool isSigned, bool isFloat, bool bigEndian)
{
  unsigned char v[8];
  for (int i = 0; i < size; ++i)
  {
    v[i] = bigEndian ? b[size - 1 - i] : b[i];
  }
  // The host is little-endian (x86-64, aarch64 Linux).
  if (isFloat)
  {
    if (size == 4)
    {
      float f;
      std::memcpy(&f, v, 4);
      return f;
    }
    double d;
    std::memcpy(&d, v, 8);
    return d;
  }
  std::uint64_t u = 0;
  std::memcpy(&u, v, static_cast<size_t>(size));
  if (isSigned && size < 8 && (u >> (8 * size - 1)) & 1u)
  {
    return static_cast<double>(static_cast<std::int64_t>(u | (~std::uint64_t(0) << (8 * size))));
  }
  return static_cast<double>(u);
}

void CheckPly(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
  {
    Fail("cannot open the file");
  }
  const PlyHeader header = ReadPlyHeader(in);
  PlyWalk walk;
  walk.Vertices = VertexElement(header)->Count;
  CheckFaceElement(header);
  if (header.Format == PlyFormat::Ascii)
  {
    AsciiBody body(in, header.DataOffset);
    for (const auto& e : header.Elements)
    {
      CheckAsciiElement(body, walk, e);
    }
    return;
  }
  in.clear();
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  BinaryBody body(in, header.DataOffset, size, header.Format == PlyFormat::BinaryBigEndian);
  for (const auto& e : header.Elements)
  {
    CheckBinaryElement(body, walk, e);
  }
}
}
