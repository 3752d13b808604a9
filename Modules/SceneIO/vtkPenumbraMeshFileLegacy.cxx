// vtkPenumbraMeshFileCheck: the legacy VTK (.vtk) check, the points and cell blocks of POLYDATA
// and UNSTRUCTURED_GRID and the declared sizes of attribute and field data.

#include "vtkPenumbraMeshFileCheckInternals.h"

#include "vtksys/SystemTools.hxx"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>

using namespace penumbra_mesh_check;

namespace
{
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
}

namespace penumbra_mesh_check
{
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
}
