// vtkPenumbraMeshFileCheck: the OBJ (Wavefront) check, the indices of f, l and p statements.

#include "vtkPenumbraMeshFileCheckInternals.h"

#include <cerrno>
#include <cstdlib>
#include <fstream>

using namespace penumbra_mesh_check;

namespace
{
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
}

namespace penumbra_mesh_check
{
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
}
