#include "vtkPenumbraMeshFileCheck.h"

#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkCellType.h"
#include "vtkObjectFactory.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"
#include "vtksys/SystemTools.hxx"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace
{
// The first problem found; the message is the sentence the user reads.
struct FileProblem : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

[[noreturn]] void Fail(const std::string& what)
{
  throw FileProblem(what);
}

// VTK's vtkPLY reads ASCII lines (header and records) into a 4096-byte buffer with fgets and
// overwrites its last two bytes: a longer line is silently split into two records.
constexpr size_t PlyMaxLine = 4094;

// More properties per element than any mesh has; keeps count x record size inside 64 bits.
constexpr size_t PlyMaxProperties = 4096;

// Element counts beyond this do not fit the int vtkPLY stores them in.
constexpr long long PlyMaxCount = std::numeric_limits<int>::max();

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

//------------------------------------------------------------------------------------------
// OBJ (Wavefront): indices of f, l and p statements

// One vertex reference of a statement: which list it indexes and the 1-based index given.
struct ObjReference
{
  long long Line;
  int List;        // 0 v, 1 vt, 2 vn
  long long Index; // absolute, 1-based, after resolving a negative (relative) index
};

const char* const ObjListNames[3] = { "vertex", "texture coordinate", "normal" };

long long ObjIndex(const std::string& text, long long line, long long defined, int list)
{
  errno = 0;
  char* end = nullptr;
  const long long i = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE)
  {
    Fail("OBJ line " + std::to_string(line) + ": \"" + text + "\" is not a " + ObjListNames[list] +
      " index");
  }
  if (i == 0)
  {
    Fail("OBJ line " + std::to_string(line) + ": " + ObjListNames[list] +
      " index 0 (OBJ indices start at 1)");
  }
  // A negative index counts back from the last one defined so far.
  if (i < 0 && defined + i + 1 < 1)
  {
    Fail("OBJ line " + std::to_string(line) + ": relative " + ObjListNames[list] + " index " +
      text + " reaches before the first one (" + std::to_string(defined) + " defined so far)");
  }
  return i < 0 ? defined + i + 1 : i;
}

void CheckObj(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
  {
    Fail("cannot open the file");
  }
  long long defined[3] = { 0, 0, 0 };
  std::vector<ObjReference> refs;
  std::string line, joined;
  long long number = 0;
  while (std::getline(in, line))
  {
    ++number;
    if (!line.empty() && line.back() == '\r')
    {
      line.pop_back();
    }
    if (!line.empty() && line.back() == '\\')
    {
      joined += line.substr(0, line.size() - 1) + " ";
      continue;
    }
    joined += line;
    const auto w = Words(joined);
    joined.clear();
    if (w.empty())
    {
      continue;
    }
    if (w[0] == "v" || w[0] == "vt" || w[0] == "vn")
    {
      const int list = w[0] == "v" ? 0 : w[0] == "vt" ? 1 : 2;
      const size_t needed = list == 1 ? 2 : 3;
      for (size_t k = 1; k <= needed; ++k)
      {
        char* end = nullptr;
        if (k >= w.size() || (std::strtod(w[k].c_str(), &end), *end != '\0'))
        {
          Fail("OBJ line " + std::to_string(number) + ": a \"" + w[0] + "\" needs " +
            std::to_string(needed) + " numbers");
        }
      }
      ++defined[list];
      continue;
    }
    if (w[0] != "f" && w[0] != "l" && w[0] != "p")
    {
      continue;
    }
    for (size_t k = 1; k < w.size(); ++k)
    {
      // v, v/vt, v//vn or v/vt/vn
      size_t start = 0;
      for (int list = 0; list < 3 && start <= w[k].size(); ++list)
      {
        const size_t slash = w[k].find('/', start);
        const std::string part =
          w[k].substr(start, slash == std::string::npos ? std::string::npos : slash - start);
        if (!part.empty() || list == 0)
        {
          refs.push_back({ number, list, ObjIndex(part, number, defined[list], list) });
        }
        if (slash == std::string::npos)
        {
          break;
        }
        start = slash + 1;
      }
    }
  }
  for (const auto& r : refs)
  {
    if (r.Index < 1 || r.Index > defined[r.List])
    {
      Fail("OBJ line " + std::to_string(r.Line) + ": " + ObjListNames[r.List] + " " +
        std::to_string(r.Index) + " does not exist (the file has " +
        std::to_string(defined[r.List]) + ")");
    }
  }
}

//------------------------------------------------------------------------------------------
// Legacy VTK (.vtk): points and cell blocks of POLYDATA and UNSTRUCTURED_GRID

// Reads a legacy file the way vtkDataReader does: keywords and ASCII values are words;
// BINARY values are big-endian and start after the keyword line's end of line.
class LegacyCursor
{
public:
  LegacyCursor(std::string data, bool binary)
    : Data(std::move(data))
    , Binary(binary)
  {
  }

  size_t Pos = 0;

  bool Word(std::string& w)
  {
    w.clear();
    while (this->Pos < this->Data.size() &&
      std::isspace(static_cast<unsigned char>(this->Data[this->Pos])))
    {
      ++this->Pos;
    }
    while (this->Pos < this->Data.size() &&
      !std::isspace(static_cast<unsigned char>(this->Data[this->Pos])))
    {
      w.push_back(this->Data[this->Pos++]);
    }
    return !w.empty();
  }

  std::string Line()
  {
    const size_t end = this->Data.find('\n', this->Pos);
    std::string line =
      this->Data.substr(this->Pos, end == std::string::npos ? std::string::npos : end - this->Pos);
    this->Pos = end == std::string::npos ? this->Data.size() : end + 1;
    if (!line.empty() && line.back() == '\r')
    {
      line.pop_back();
    }
    return line;
  }

  // Binary data begins after the end of the keyword line.
  void StartData()
  {
    if (this->Binary)
    {
      this->Line();
    }
  }

  // One value of `size` bytes (binary) or one number word (ASCII); false if missing.
  bool Value(int size, bool isSigned, bool isFloat, double& v)
  {
    if (!this->Binary)
    {
      std::string w;
      if (!this->Word(w))
      {
        return false;
      }
      // vtkDataReader reads integers with operator>>: "-0.0" or "1e3" stops it mid-word.
      char* end = nullptr;
      errno = 0;
      v = isFloat ? std::strtod(w.c_str(), &end)
                  : static_cast<double>(std::strtoll(w.c_str(), &end, 10));
      return *end == '\0' && errno != ERANGE;
    }
    if (this->Pos + static_cast<size_t>(size) > this->Data.size())
    {
      return false;
    }
    v = DecodeBinary(reinterpret_cast<const unsigned char*>(this->Data.data() + this->Pos), size,
      isSigned, isFloat, true);
    this->Pos += static_cast<size_t>(size);
    return true;
  }

  // Skips n values of `size` bytes in a binary file; false if the file is shorter.
  bool SkipBinary(long long n, int size)
  {
    if (n > static_cast<long long>((this->Data.size() - this->Pos) / static_cast<size_t>(size)))
    {
      return false;
    }
    this->Pos += static_cast<size_t>(n) * static_cast<size_t>(size);
    return true;
  }

  bool IsBinary() const { return this->Binary; }

private:
  std::string Data;
  bool Binary;
};

// Byte size of a legacy data type name (vtkDataReader's names); 0 if unknown.
int LegacyTypeSize(const std::string& type, bool& isFloat, bool& isSigned)
{
  const std::string t = vtksys::SystemTools::LowerCase(type);
  isFloat = (t == "float" || t == "double");
  isSigned = !(t.rfind("unsigned", 0) == 0 || t == "vtktypeuint64" || t == "vtktypeuint32");
  if (t == "char" || t == "unsigned_char" || t == "signed_char")
    return 1;
  if (t == "short" || t == "unsigned_short")
    return 2;
  if (t == "int" || t == "unsigned_int" || t == "float" || t == "vtkidtype" ||
    t == "vtktypeint32" || t == "vtktypeuint32")
    return 4;
  if (t == "long" || t == "unsigned_long" || t == "double" || t == "vtktypeint64" ||
    t == "vtktypeuint64")
    return 8;
  return 0;
}

long long LegacyCount(const std::string& word, const std::string& keyword)
{
  errno = 0;
  char* end = nullptr;
  const long long n = std::strtoll(word.c_str(), &end, 10);
  if (word.empty() || *end != '\0' || errno == ERANGE || n < 0 || n > PlyMaxCount)
  {
    Fail("legacy VTK " + keyword + ": the count \"" + word + "\" is not a whole number from 0 to " +
      std::to_string(PlyMaxCount));
  }
  return n;
}

long long LegacyPoints(LegacyCursor& in)
{
  std::string countWord, type;
  in.Word(countWord);
  in.Word(type);
  const long long n = LegacyCount(countWord, "POINTS");
  bool isFloat = false, isSigned = true;
  const int size = LegacyTypeSize(type, isFloat, isSigned);
  if (size == 0)
  {
    Fail("legacy VTK POINTS: unknown data type \"" + type + "\"");
  }
  in.StartData();
  if (in.IsBinary())
  {
    if (!in.SkipBinary(3 * n, size))
    {
      Fail("legacy VTK file ends inside its " + std::to_string(n) + " POINTS");
    }
    return n;
  }
  for (long long i = 0; i < 3 * n; ++i)
  {
    double v;
    if (!in.Value(size, isSigned, isFloat, v))
    {
      Fail("legacy VTK POINTS: coordinate " + std::to_string(i + 1) + " of " +
        std::to_string(3 * n) + " is missing or not a number");
    }
  }
  return n;
}

// Classic layout: `KEYWORD cells size` then, per cell, its point count and point ids.
void LegacyCellsClassic(
  LegacyCursor& in, const std::string& keyword, long long cells, long long size, long long points)
{
  in.StartData();
  long long used = 0;
  auto next = [&](const char* what, long long cell)
  {
    double v = 0;
    if (used >= size || !in.Value(4, true, false, v) || v != std::floor(v))
    {
      Fail("legacy VTK " + keyword + ": cell " + std::to_string(cell + 1) + " of " +
        std::to_string(cells) + ": " + what +
        " is missing, not an integer, or beyond the declared size " + std::to_string(size));
    }
    ++used;
    return static_cast<long long>(v);
  };
  for (long long c = 0; c < cells; ++c)
  {
    const long long n = next("the point count", c);
    if (n < 0 || n > size)
    {
      Fail("legacy VTK " + keyword + ": cell " + std::to_string(c + 1) + " has the point count " +
        std::to_string(n));
    }
    for (long long k = 0; k < n; ++k)
    {
      const long long id = next("a point id", c);
      if (id < 0 || id >= points)
      {
        Fail("legacy VTK " + keyword + ": cell " + std::to_string(c + 1) + " uses point " +
          std::to_string(id) + " but there are only " + std::to_string(points) + " points");
      }
    }
  }
  if (used != size)
  {
    Fail("legacy VTK " + keyword + ": " + std::to_string(cells) + " cells use " +
      std::to_string(used) + " values, the header declares " + std::to_string(size));
  }
}

// Version 5 layout: `KEYWORD offsets connectivity`, then OFFSETS and CONNECTIVITY arrays.
void LegacyCellsOffsets(
  LegacyCursor& in, const std::string& keyword, long long offsets, long long size, long long points)
{
  auto array = [&](const char* name, long long n, long long lo, long long hi, bool increasing)
  {
    std::string word, type;
    in.Word(word);
    in.Word(type);
    bool isFloat = false, isSigned = true;
    const int bytes = LegacyTypeSize(type, isFloat, isSigned);
    if (word != name || bytes == 0 || isFloat)
    {
      Fail("legacy VTK " + keyword + ": expected \"" + name + " <integer type>\", found \"" + word +
        " " + type + "\"");
    }
    in.StartData();
    double last = -1;
    for (long long i = 0; i < n; ++i)
    {
      double v = 0;
      if (!in.Value(bytes, isSigned, false, v) || v != std::floor(v) || v < lo || v >= hi ||
        (increasing && v < last))
      {
        Fail("legacy VTK " + keyword + ": " + name + " value " + std::to_string(i + 1) + " of " +
          std::to_string(n) + " is missing or outside [" + std::to_string(lo) + ", " +
          std::to_string(hi) + ")");
      }
      last = v;
    }
    if (increasing && n > 0 && (last != static_cast<double>(size)))
    {
      Fail("legacy VTK " + keyword + ": the last offset must equal the connectivity size " +
        std::to_string(size));
    }
  };
  array("OFFSETS", offsets, 0, size + 1, true);
  array("CONNECTIVITY", size, 0, points, false);
}

long long LegacyBoundedCount(
  LegacyCursor& in, const std::string& keyword, long long lo, long long hi)
{
  std::string w;
  in.Word(w);
  const long long n = LegacyCount(w, keyword);
  if (n < lo || n > hi)
  {
    Fail("legacy VTK " + keyword + ": " + std::to_string(n) + " is outside " + std::to_string(lo) +
      ".." + std::to_string(hi));
  }
  return n;
}

// `FIELD name arrays` and each array's `name components tuples type` header. Returns false
// where the check must stop: binary values cannot be skipped without parsing their types.
bool LegacyField(LegacyCursor& in, long long budget)
{
  std::string name, word;
  in.Word(name);
  const long long arrays = LegacyBoundedCount(in, "FIELD arrays", 0, 1 << 20);
  for (long long a = 0; a < arrays; ++a)
  {
    std::string arrayName, type;
    in.Word(arrayName);
    const long long components = LegacyBoundedCount(in, "FIELD array components", 0, 1 << 20);
    const long long n = LegacyBoundedCount(in, "FIELD array tuples", 0, PlyMaxCount);
    if (components * n > budget)
    {
      Fail("legacy VTK FIELD array declares " + std::to_string(components * n) +
        " values, more than the file can hold");
    }
    in.Word(type);
    if (in.IsBinary())
    {
      return false;
    }
    for (long long v = 0; v < components * n && in.Word(word); ++v)
    {
    }
  }
  return true;
}

long long LegacyBytesBudget(const LegacyCursor& in, size_t fileSize)
{
  // Fewest bytes one value takes: a digit and a separator in ASCII, a byte in BINARY.
  return static_cast<long long>(fileSize) / (in.IsBinary() ? 1 : 2) + 1;
}

// Attribute and field data: values are not checked (vtkDataReader parses them), but every
// declared size is, against what the file can hold. vtkDataReader allocates what a header
// declares before reading: `SCALARS s float 2147483647` (components) made it allocate and
// clear tens of gigabytes for a 4-point file.
void LegacyAttributes(LegacyCursor& in, long long points, long long cells, size_t fileSize)
{
  const long long budget = LegacyBytesBudget(in, fileSize);
  long long tuples = points; // of the current POINT_DATA or CELL_DATA section
  std::string word;
  auto count = [&](const std::string& keyword, long long lo, long long hi)
  { return LegacyBoundedCount(in, keyword, lo, hi); };
  auto fits = [&](const std::string& keyword, long long values)
  {
    if (values > budget)
    {
      Fail("legacy VTK " + keyword + " declares " + std::to_string(values) +
        " values, more than the file can hold");
    }
  };
  while (in.Word(word))
  {
    std::string name, type;
    if (word == "POINT_DATA" || word == "CELL_DATA")
    {
      const long long expected = word == "POINT_DATA" ? points : cells;
      tuples = count(word, 0, PlyMaxCount);
      if (expected >= 0 && tuples != expected)
      {
        Fail("legacy VTK " + word + " " + std::to_string(tuples) + " does not match the " +
          std::to_string(expected) + (word == "POINT_DATA" ? " points" : " cells"));
      }
    }
    else if (word == "SCALARS")
    {
      in.Word(name);
      in.Word(type);
      // The component count is optional; the next word is then LOOKUP_TABLE.
      const size_t at = in.Pos;
      std::string next;
      in.Word(next);
      long long components = 1;
      if (next != "LOOKUP_TABLE")
      {
        in.Pos = at;
        components = count("SCALARS components", 1, 4);
      }
      fits("SCALARS", tuples * components);
    }
    else if (word == "COLOR_SCALARS")
    {
      in.Word(name);
      fits("COLOR_SCALARS", tuples * count("COLOR_SCALARS components", 1, 4));
    }
    else if (word == "TEXTURE_COORDINATES")
    {
      in.Word(name);
      fits("TEXTURE_COORDINATES", tuples * count("TEXTURE_COORDINATES dimension", 1, 3));
    }
    else if (word == "VECTORS" || word == "NORMALS" || word == "TENSORS")
    {
      fits(word, tuples * (word == "TENSORS" ? 9 : 3));
    }
    else if (word == "LOOKUP_TABLE")
    {
      in.Word(name);
      // "LOOKUP_TABLE default" names a table; a table itself gives its size.
      const size_t at = in.Pos;
      std::string size;
      in.Word(size);
      char* end = nullptr;
      const long long n = std::strtoll(size.c_str(), &end, 10);
      if (!size.empty() && *end == '\0')
      {
        fits("LOOKUP_TABLE", 4 * std::max(n, 0LL));
      }
      in.Pos = at;
    }
    else if (word == "FIELD" && !LegacyField(in, budget))
    {
      return;
    }
  }
}

void CheckLegacy(const std::string& path)
{
  std::ifstream file(path, std::ios::binary);
  if (!file)
  {
    Fail("cannot open the file");
  }
  std::string data((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  LegacyCursor head(data, false);
  const std::string magic = head.Line();
  if (magic.rfind("# vtk DataFile Version", 0) != 0)
  {
    Fail("not a legacy VTK file (the first line must start with \"# vtk DataFile Version\")");
  }
  const double version = std::atof(magic.c_str() + 22);
  head.Line(); // title
  const auto format = Words(head.Line());
  if (format.size() != 1 || (format[0] != "ASCII" && format[0] != "BINARY"))
  {
    Fail("legacy VTK file: the third line must be ASCII or BINARY");
  }
  const size_t fileSize = data.size();
  LegacyCursor in(std::move(data), format[0] == "BINARY");
  in.Pos = head.Pos;
  std::string word;
  long long points = -1;
  long long cells = 0;
  while (in.Word(word))
  {
    if (word == "DATASET")
    {
      std::string type;
      in.Word(type);
      if (type != "POLYDATA" && type != "UNSTRUCTURED_GRID")
      {
        return; // implicit geometry: nothing indexes points
      }
    }
    else if (word == "POINTS")
    {
      points = LegacyPoints(in);
    }
    else if (word == "VERTICES" || word == "LINES" || word == "POLYGONS" ||
      word == "TRIANGLE_STRIPS" || word == "CELLS")
    {
      std::string a, b;
      in.Word(a);
      in.Word(b);
      const long long first = LegacyCount(a, word);
      const long long size = LegacyCount(b, word);
      if (points < 0)
      {
        Fail("legacy VTK " + word + " come before any POINTS");
      }
      cells += version >= 5.0 ? std::max(first - 1, 0LL) : first;
      if (version >= 5.0)
      {
        LegacyCellsOffsets(in, word, first, size, points);
      }
      else
      {
        LegacyCellsClassic(in, word, first, size, points);
      }
    }
    else if (word == "CELL_TYPES")
    {
      std::string a;
      in.Word(a);
      const long long n = LegacyCount(a, word);
      in.StartData();
      for (long long i = 0; i < n; ++i)
      {
        double v = 0;
        if (!in.Value(4, true, false, v) || v < 0 || v > 255 || v != std::floor(v))
        {
          Fail("legacy VTK CELL_TYPES: type " + std::to_string(i + 1) + " of " + std::to_string(n) +
            " is missing or not a cell type");
        }
      }
    }
    else if (word == "FIELD")
    {
      if (!LegacyField(in, LegacyBytesBudget(in, fileSize)))
      {
        return;
      }
    }
    else if (word == "POINT_DATA" || word == "CELL_DATA")
    {
      in.Pos -= word.size();
      LegacyAttributes(in, points, cells, fileSize);
      return;
    }
    else if (word == "METADATA")
    {
      return; // information keys only
    }
    else
    {
      // vtkPolyDataReader misreads what follows an unknown keyword (a crash in ReadString).
      std::string shown = word.substr(0, 40);
      for (auto& c : shown)
      {
        c = std::isprint(static_cast<unsigned char>(c)) ? c : '?';
      }
      Fail("legacy VTK file: unknown keyword \"" + shown + "\"");
    }
  }
}

// Point count a fixed-size VTK cell type needs (vtkCellType.h); 0 for a variable count
// (at least `minimum`), -1 for a type the surface filter cannot take apart safely.
int CellTypePoints(int type, int& minimum)
{
  minimum = 0;
  switch (type)
  {
    case VTK_EMPTY_CELL:
      return 0;
    case VTK_VERTEX:
      return 1;
    case VTK_POLY_VERTEX:
      minimum = 1;
      return 0;
    case VTK_LINE:
      return 2;
    case VTK_POLY_LINE:
      minimum = 2;
      return 0;
    case VTK_TRIANGLE:
      return 3;
    case VTK_TRIANGLE_STRIP:
      minimum = 3;
      return 0;
    case VTK_POLYGON:
      minimum = 3;
      return 0;
    case VTK_PIXEL:
      return 4;
    case VTK_QUAD:
      return 4;
    case VTK_TETRA:
      return 4;
    case VTK_VOXEL:
      return 8;
    case VTK_HEXAHEDRON:
      return 8;
    case VTK_WEDGE:
      return 6;
    case VTK_PYRAMID:
      return 5;
    case VTK_PENTAGONAL_PRISM:
      return 10;
    case VTK_HEXAGONAL_PRISM:
      return 12;
    case VTK_QUADRATIC_EDGE:
      return 3;
    case VTK_QUADRATIC_TRIANGLE:
      return 6;
    case VTK_QUADRATIC_QUAD:
      return 8;
    case VTK_QUADRATIC_TETRA:
      return 10;
    case VTK_QUADRATIC_HEXAHEDRON:
      return 20;
    case VTK_QUADRATIC_WEDGE:
      return 15;
    case VTK_QUADRATIC_PYRAMID:
      return 13;
    case VTK_BIQUADRATIC_QUAD:
      return 9;
    case VTK_TRIQUADRATIC_HEXAHEDRON:
      return 27;
    case VTK_QUADRATIC_LINEAR_QUAD:
      return 6;
    case VTK_QUADRATIC_LINEAR_WEDGE:
      return 12;
    case VTK_BIQUADRATIC_QUADRATIC_WEDGE:
      return 18;
    case VTK_BIQUADRATIC_QUADRATIC_HEXAHEDRON:
      return 24;
    case VTK_BIQUADRATIC_TRIANGLE:
      return 7;
    case VTK_CUBIC_LINE:
      return 4;
    default:
      return -1;
  }
}

// A cell type that needs more points than the cell has makes vtkDataSetSurfaceFilter read
// past the cell's ids.
std::string CheckCellTypes(vtkUnstructuredGrid* grid)
{
  const vtkIdType cells = grid->GetNumberOfCells();
  vtkUnsignedCharArray* types = grid->GetCellTypesArray();
  if (cells > 0 && (!types || types->GetNumberOfValues() != cells))
  {
    return std::to_string(cells) + " cells but " +
      std::to_string(types ? types->GetNumberOfValues() : 0) + " cell types";
  }
  for (vtkIdType c = 0; c < cells; ++c)
  {
    const int type = types->GetValue(c);
    const vtkIdType n = grid->GetCells()->GetCellSize(c);
    int minimum = 0;
    const int needed = CellTypePoints(type, minimum);
    if (needed < 0)
    {
      return "cell " + std::to_string(c) + " has the unsupported cell type " + std::to_string(type);
    }
    if ((needed > 0 && n != needed) || (needed == 0 && n < minimum))
    {
      return "cell " + std::to_string(c) + " of type " + std::to_string(type) + " has " +
        std::to_string(n) + " points, the type needs " +
        std::to_string(needed > 0 ? needed : minimum) + (needed > 0 ? "" : " or more");
    }
  }
  return std::string();
}

std::string CheckCells(vtkCellArray* cells, vtkIdType points, const char* kind)
{
  if (!cells)
  {
    return std::string();
  }
  auto it = vtk::TakeSmartPointer(cells->NewIterator());
  vtkIdType n = 0;
  const vtkIdType* ids = nullptr;
  for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell())
  {
    it->GetCurrentCell(n, ids);
    for (vtkIdType k = 0; k < n; ++k)
    {
      if (ids[k] < 0 || ids[k] >= points)
      {
        return std::string(kind) + " " + std::to_string(it->GetCurrentCellId()) + " uses point " +
          std::to_string(ids[k]) + " but there are only " + std::to_string(points) + " points";
      }
    }
  }
  return std::string();
}
}

vtkStandardNewMacro(vtkPenumbraMeshFileCheck);

vtkPenumbraMeshFileCheck::vtkPenumbraMeshFileCheck()
  : FileName(nullptr)
{
}

vtkPenumbraMeshFileCheck::~vtkPenumbraMeshFileCheck()
{
  this->SetFileName(nullptr);
}

int vtkPenumbraMeshFileCheck::Check()
{
  this->ErrorMessage.clear();
  if (!this->FileName || !*this->FileName)
  {
    this->ErrorMessage = "no file name given";
    return 0;
  }
  const std::string path = this->FileName;
  const std::string ext =
    vtksys::SystemTools::LowerCase(vtksys::SystemTools::GetFilenameLastExtension(path));
  try
  {
    if (ext == ".ply")
    {
      CheckPly(path);
    }
    else if (ext == ".obj")
    {
      CheckObj(path);
    }
    else if (ext == ".vtk")
    {
      CheckLegacy(path);
    }
  }
  catch (const FileProblem& e)
  {
    this->ErrorMessage = e.what();
  }
  catch (const std::exception& e)
  {
    this->ErrorMessage = std::string("cannot be checked: ") + e.what();
  }
  return this->ErrorMessage.empty() ? 1 : 0;
}

std::string vtkPenumbraMeshFileCheck::CheckConnectivity(vtkDataSet* data)
{
  if (auto* pd = vtkPolyData::SafeDownCast(data))
  {
    const vtkIdType n = pd->GetNumberOfPoints();
    std::string why = CheckCells(pd->GetVerts(), n, "vertex cell");
    why = why.empty() ? CheckCells(pd->GetLines(), n, "line") : why;
    why = why.empty() ? CheckCells(pd->GetPolys(), n, "polygon") : why;
    why = why.empty() ? CheckCells(pd->GetStrips(), n, "triangle strip") : why;
    return why;
  }
  if (auto* ug = vtkUnstructuredGrid::SafeDownCast(data))
  {
    const std::string why = CheckCells(ug->GetCells(), ug->GetNumberOfPoints(), "cell");
    return why.empty() ? CheckCellTypes(ug) : why;
  }
  return std::string();
}

void vtkPenumbraMeshFileCheck::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "ErrorMessage: " << this->ErrorMessage << "\n";
}
