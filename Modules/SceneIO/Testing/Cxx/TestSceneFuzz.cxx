// Fuzz run of the scene reader and the mesh loaders: mutated JSON scenes and PLY, OBJ, VTK and
// STL files (truncation, flipped bytes, huge or negative counts, NaN/Inf, wrong JSON types,
// duplicated lights). Every case must end as a valid scene (read and extracted) or as one
// clear error that names the scene file; a crash, a hang or a silent failure fails the test.
//
// Each case runs in a forked child with a memory limit, so a crash inside a VTK reader is
// counted rather than ending the run, and a case that takes longer than the time limit is
// killed and counted as a hang. The mutations are drawn from a fixed-state generator, so a
// run is reproducible; failing cases are written to the temporary folder for replay.
//
//   vtkPenumbraSceneIOCxxTests TestSceneFuzz [--cases N] [--start S] [--keep DIR]
//
// ctest runs a short bounded run; docs/hardening.md records the large runs.

#include "vtkNew.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraSceneReader.h"
#include "vtkRenderer.h"

#include "PenumbraTestMacros.h"

#include <nlohmann/json.hpp>

#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

using json = nlohmann::json;

namespace
{
//------------------------------------------------------------------------------------------
// Starts: small valid files of every kind the scene reader loads.

std::string BinaryPly(bool bigEndian)
{
  // Tetrahedron: 4 vertices (x y z + uchar colour), 4 triangles.
  std::string s = std::string("ply\nformat ") +
    (bigEndian ? "binary_big_endian" : "binary_little_endian") +
    " 1.0\ncomment fuzz start\nelement vertex 4\nproperty float x\nproperty float y\nproperty "
    "float z\nproperty uchar red\nelement face 4\nproperty list uchar int "
    "vertex_indices\nend_header\n";
  auto put = [&](const void* p, size_t n)
  {
    const auto* b = static_cast<const unsigned char*>(p);
    for (size_t i = 0; i < n; ++i)
    {
      s.push_back(static_cast<char>(bigEndian ? b[n - 1 - i] : b[i]));
    }
  };
  const float v[4][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
  for (const auto& p : v)
  {
    for (float x : p)
    {
      put(&x, 4);
    }
    s.push_back('\x80');
  }
  const int f[4][3] = { { 0, 2, 1 }, { 0, 1, 3 }, { 0, 3, 2 }, { 1, 2, 3 } };
  for (const auto& t : f)
  {
    s.push_back('\x03');
    for (int i : t)
    {
      put(&i, 4);
    }
  }
  return s;
}

const char* const AsciiPly =
  "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
  "property float y\nproperty float z\nproperty float nx\nelement face 4\n"
  "property list uchar int vertex_indices\nend_header\n"
  "0 0 0 1\n1 0 0 1\n0 1 0 1\n0 0 1 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

const char* const Obj = "# cube corner\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
                        "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nvn 0 0 -1\n"
                        "f 1/1/2 3/3/2 2/2/2\nf 1//2 4//2 3//2\nf -1 -4 -5\nf 1 2 5\nl 1 2\n";

const char* const LegacyPolyData =
  "# vtk DataFile Version 3.0\nfuzz start\nASCII\nDATASET POLYDATA\n"
  "POINTS 4 float\n0 0 0 1 0 0 0 1 0 0 0 1\n"
  "POLYGONS 4 16\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"
  "POINT_DATA 4\nSCALARS s float 1\nLOOKUP_TABLE default\n0 1 2 3\n";

const char* const LegacyGrid =
  "# vtk DataFile Version 3.0\nfuzz start\nASCII\nDATASET UNSTRUCTURED_GRID\n"
  "POINTS 5 double\n0 0 0 1 0 0 0 1 0 0 0 1 1 1 1\n"
  "CELLS 2 10\n4 0 1 2 3\n4 1 2 3 4\nCELL_TYPES 2\n10\n10\n";

const char* const AsciiStl =
  "solid fuzz\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
  "vertex 0 1 0\nendloop\nendfacet\nfacet normal 1 0 0\nouter loop\n"
  "vertex 0 0 0\nvertex 0 1 0\nvertex 0 0 1\nendloop\nendfacet\nendsolid fuzz\n";

std::string BinaryStl()
{
  std::string s(80, ' ');
  const std::uint32_t n = 2;
  s.append(reinterpret_cast<const char*>(&n), 4);
  const float tris[2][12] = { { 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0 },
    { 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1 } };
  for (const auto& t : tris)
  {
    s.append(reinterpret_cast<const char*>(t), sizeof(t));
    s.append(2, '\0');
  }
  return s;
}

struct MeshStart
{
  const char* Extension;
  std::string Text;
  bool Binary;
};

std::vector<MeshStart> MeshStarts()
{
  return { { ".ply", AsciiPly, false }, { ".ply", BinaryPly(false), true },
    { ".ply", BinaryPly(true), true }, { ".obj", Obj, false }, { ".vtk", LegacyPolyData, false },
    { ".vtk", LegacyGrid, false }, { ".stl", AsciiStl, false }, { ".stl", BinaryStl(), true } };
}

json SceneStart(int which)
{
  if (which == 0)
  {
    return json::parse(R"({
      "description": "fuzz start with every light type",
      "image": {"width": 64, "height": 48}, "background": [0.1, 0.2, 0.3],
      "camera": {"position": [3, -4, 3], "focal_point": [0, 0, 0], "view_up": [0, 0, 1],
                 "view_angle": 30, "clipping_range": [0.1, 100]},
      "objects": [
        {"name": "mesh", "file": "MESH",
         "transform": {"scale": [1, 2, 1], "rotate": [30, 0, 0, 1], "translate": [0, 0, 0.5]},
         "color": [0.8, 0.2, 0.2],
         "material": {"model": "phong", "ambient": 0.1, "diffuse": 0.9, "specular": 0.1,
                      "specular_power": 20}},
        {"name": "ground", "generator": {"type": "plane", "origin": [-2, -2, 0],
         "point1": [2, -2, 0], "point2": [-2, 2, 0], "resolution": 4}},
        {"name": "box", "generator": {"type": "box", "bounds": [0, 0.5, 0, 0.5, 0, 0.5]},
         "opacity": 0.5, "cast_shadows": false},
        {"name": "ball", "generator": {"type": "sphere", "center": [1, 1, 0.5], "radius": 0.3,
         "resolution": 8}, "material": {"model": "pbr", "metallic": 0.2, "roughness": 0.5}},
        {"name": "city", "generator": {"type": "city_block", "rows": 1, "columns": 2,
         "spacing": 1, "min_height": 0.2, "max_height": 0.5, "ground": false}}
      ],
      "lights": [
        {"type": "directional", "direction": [0.2, 0.1, -1], "intensity": 0.8},
        {"type": "directional", "elevation": 40, "azimuth": 120, "on": false},
        {"type": "spot", "position": [0, 0, 4], "focal_point": [0, 0, 0], "cone_angle": 30,
         "exponent": 2, "color": [1, 0.9, 0.8]},
        {"type": "point", "position": [1, -1, 3]},
        {"type": "area", "position": [0, 0, 3], "size": [1, 0.5], "normal": [0, 0, -1],
         "up": [0, 1, 0], "samples": 2},
        {"type": "linear", "position": [0, 1, 3], "length": 1, "axis": [1, 0, 0],
         "focal_point": [0, 1, 0], "samples": 3}
      ],
      "technique": {"name": "raytraced"}
    })");
  }
  return json::parse(R"({
    "camera": {"auto": true, "azimuth": 20, "elevation": 10, "zoom": 1.2, "parallel_scale": 2},
    "objects": [
      {"file": "MESH", "transform": {"matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}},
      {"generator": {"type": "room", "size": [4, 4, 2], "furniture": false}, "visible": true}
    ],
    "lights": [{"type": "point", "position": [0, 0, 1]}],
    "technique": {"name": "shadowmap", "resolution": 256}
  })");
}

void SetMesh(json& node, const std::string& mesh)
{
  if (node.is_object())
  {
    for (auto& [key, value] : node.items())
    {
      if (key == "file" && value == "MESH")
      {
        value = mesh;
      }
      else
      {
        SetMesh(value, mesh);
      }
    }
  }
  else if (node.is_array())
  {
    for (auto& v : node)
    {
      SetMesh(v, mesh);
    }
  }
}

//------------------------------------------------------------------------------------------
// Mutations

using Rng = std::mt19937_64;

size_t Pick(Rng& rng, size_t n)
{
  return n == 0 ? 0 : std::uniform_int_distribution<size_t>(0, n - 1)(rng);
}

const char* const HostileNumbers[] = { "nan", "NaN", "inf", "-inf", "Infinity", "-1", "0",
  "-2147483648", "2147483647", "2147483648", "4294967295", "4294967296", "99999999999999999999",
  "1e308", "-1e308", "1e-320", "3.5", "-0.0", "abc", "", "0x10", "1e", "--1" };

// Positions of the number-like tokens (digits with signs, dots and exponents) in a text.
std::vector<std::pair<size_t, size_t>> NumberTokens(const std::string& s)
{
  std::vector<std::pair<size_t, size_t>> tokens;
  size_t i = 0;
  while (i < s.size())
  {
    if (std::isdigit(static_cast<unsigned char>(s[i])) ||
      ((s[i] == '-' || s[i] == '.') && i + 1 < s.size() &&
        std::isdigit(static_cast<unsigned char>(s[i + 1]))))
    {
      size_t j = i + 1;
      while (j < s.size() &&
        (std::isalnum(static_cast<unsigned char>(s[j])) || s[j] == '.' || s[j] == '-' ||
          s[j] == '+'))
      {
        ++j;
      }
      tokens.emplace_back(i, j - i);
      i = j;
    }
    else
    {
      ++i;
    }
  }
  return tokens;
}

std::string MutateText(std::string s, Rng& rng, bool binary, std::string& how)
{
  const int kind = static_cast<int>(Pick(rng, binary ? 6 : 7));
  std::ostringstream note;
  switch (kind)
  {
    case 0: // truncation, often just after a header
    {
      const size_t header = s.find("end_header\n");
      size_t at = Pick(rng, s.size() + 1);
      if (header != std::string::npos && Pick(rng, 2) == 0)
      {
        at = header + 11 + Pick(rng, 8);
      }
      at = std::min(at, s.size());
      note << "truncate at " << at << " of " << s.size();
      s.resize(at);
      break;
    }
    case 1: // flipped bytes
    {
      const size_t n = 1 + Pick(rng, 8);
      note << "flip " << n << " bytes";
      for (size_t k = 0; k < n && !s.empty(); ++k)
      {
        s[Pick(rng, s.size())] ^= static_cast<char>(1u << Pick(rng, 8));
      }
      break;
    }
    case 2: // random bytes inserted
    {
      const size_t at = Pick(rng, s.size() + 1);
      const size_t n = 1 + Pick(rng, 16);
      note << "insert " << n << " random bytes at " << at;
      std::string junk;
      for (size_t k = 0; k < n; ++k)
      {
        junk.push_back(static_cast<char>(Pick(rng, 256)));
      }
      s.insert(at, junk);
      break;
    }
    case 3: // a range deleted or duplicated
    {
      const size_t a = Pick(rng, s.size() + 1);
      const size_t n = std::min(s.size() - a, 1 + Pick(rng, 64));
      if (Pick(rng, 2) == 0)
      {
        note << "delete " << n << " bytes at " << a;
        s.erase(a, n);
      }
      else
      {
        note << "duplicate " << n << " bytes at " << a;
        s.insert(a, s.substr(a, n));
      }
      break;
    }
    default: // a number (a count, an index, a coordinate) replaced by a hostile one
    {
      // Binary files: only the header's numbers are text.
      const size_t end = binary
        ? std::min(
            s.size(), s.find("end_header") == std::string::npos ? size_t(80) : s.find("end_header"))
        : s.size();
      auto tokens = NumberTokens(s.substr(0, end));
      if (tokens.empty())
      {
        note << "no number to replace";
        break;
      }
      const auto t = tokens[Pick(rng, tokens.size())];
      std::string value =
        HostileNumbers[Pick(rng, sizeof(HostileNumbers) / sizeof(*HostileNumbers))];
      if (Pick(rng, 3) == 0)
      {
        // A count made a little or a lot larger than the data.
        const long long old = std::atoll(s.substr(t.first, t.second).c_str());
        value = std::to_string(Pick(rng, 2) == 0 ? old + 1 : old * 1000 + 7);
      }
      note << "number \"" << s.substr(t.first, t.second) << "\" at " << t.first << " -> \"" << value
           << "\"";
      s.replace(t.first, t.second, value);
      break;
    }
  }
  how += (how.empty() ? "" : "; ") + note.str();
  return s;
}

json HostileValue(Rng& rng)
{
  switch (Pick(rng, 16))
  {
    case 0:
      return json(nullptr);
    case 1:
      return json(true);
    case 2:
      return json("text");
    case 3:
      return json::array();
    case 4:
      return json::object();
    case 5:
      return json(-1);
    case 6:
      return json(0);
    case 7:
      return json(1e308);
    case 8:
      return json(-1e308);
    case 9:
      return json(2147483648LL);
    case 10:
      return json(99999999999LL);
    case 11:
      return json(1e-320);
    case 12:
      return json::array({ 1, 2 });
    case 13:
      return json::array({ 1, 2, 3, 4 });
    case 14:
      return json::array({ "a", "b", "c" });
    default:
      return json(0.5);
  }
}

// All values in a JSON tree, as pointers, to pick one to mutate.
void Collect(json& node, std::vector<json*>& out)
{
  out.push_back(&node);
  if (node.is_object() || node.is_array())
  {
    for (auto& v : node)
    {
      Collect(v, out);
    }
  }
}

void MutateJson(json& root, Rng& rng, std::string& how)
{
  std::vector<json*> nodes;
  Collect(root, nodes);
  json* node = nodes[Pick(rng, nodes.size())];
  switch (Pick(rng, 5))
  {
    case 0:
    case 1:
      how +=
        (how.empty() ? "" : "; ") + std::string("value ") + node->dump().substr(0, 40) + " -> ";
      *node = HostileValue(rng);
      how += node->dump();
      break;
    case 2: // a key deleted or misspelt
    {
      if (!node->is_object() || node->empty())
      {
        how += (how.empty() ? "" : "; ") + std::string("no key to change");
        break;
      }
      auto it = node->begin();
      std::advance(it, static_cast<long>(Pick(rng, node->size())));
      const std::string key = it.key();
      json value = it.value();
      node->erase(key);
      if (Pick(rng, 2) == 0)
      {
        (*node)[key + "_"] = value;
      }
      how += (how.empty() ? "" : "; ") + std::string("key ") + key + " removed or renamed";
      break;
    }
    case 3: // an array element repeated (lights past the limit, many objects)
    {
      if (!node->is_array() || node->empty())
      {
        how += (how.empty() ? "" : "; ") + std::string("no array to grow");
        break;
      }
      const json item = (*node)[Pick(rng, node->size())];
      const size_t copies = 1 + Pick(rng, 40);
      for (size_t k = 0; k < copies; ++k)
      {
        json copy = item;
        if (copy.is_object() && copy.contains("name"))
        {
          copy["name"] = copy["name"].dump() + std::to_string(k);
        }
        node->push_back(copy);
      }
      how += (how.empty() ? "" : "; ") + std::string("array grown by ") + std::to_string(copies);
      break;
    }
    default: // numbers in the tree made non-finite in the text (NaN, Infinity, 1e999)
      how += (how.empty() ? "" : "; ") + std::string("text-level");
      break;
  }
}

//------------------------------------------------------------------------------------------
// Running one case

// Child exit codes; anything else (1 is what AddressSanitizer and UBSan exit with after a
// report) counts as a crash.
enum Outcome
{
  Valid = 0,
  ClearError = 20,
  UnclearError = 21,
  Crash = 22,
  Hang = 23
};

// Runs in the forked child: read, then extract the geometry every technique starts from.
[[noreturn]] void ChildRead(const std::string& scene)
{
  const int devnull = open("/dev/null", O_WRONLY);
  dup2(devnull, 1);
  dup2(devnull, 2);
  // Valid-but-huge generator settings must end as an allocation failure, not take the
  // machine's memory. (AddressSanitizer reserves terabytes of address space: no limit there.)
#ifndef __SANITIZE_ADDRESS__
  struct rlimit limit = { 2048ull << 20, 2048ull << 20 };
  setrlimit(RLIMIT_AS, &limit);
#endif
  vtkNew<vtkPenumbraSceneReader> reader;
  reader->GlobalWarningDisplayOff();
  reader->SetFileName(scene.c_str());
  int code = UnclearError;
  if (reader->Read())
  {
    vtkNew<vtkPenumbraSceneGeometry> geometry;
    geometry->GlobalWarningDisplayOff();
    if (geometry->Update(reader->GetRenderer()))
    {
      code = Valid;
    }
    else
    {
      code = std::strlen(geometry->GetErrorMessage()) > 0 ? ClearError : UnclearError;
    }
  }
  else
  {
    const std::string msg = reader->GetErrorMessage();
    code = (msg.rfind(scene + ": ", 0) == 0 && msg.size() > scene.size() + 4) ? ClearError
                                                                              : UnclearError;
  }
  _exit(code);
}

Outcome RunCase(const std::string& scene, double timeoutSeconds)
{
  std::cout.flush();
  std::cerr.flush();
  const pid_t pid = fork();
  if (pid == 0)
  {
    ChildRead(scene);
  }
  const auto start = std::chrono::steady_clock::now();
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) == 0)
  {
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >
      timeoutSeconds)
    {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      return Hang;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  if (WIFSIGNALED(status))
  {
    return Crash;
  }
  const int code = WEXITSTATUS(status);
  return code == Valid     ? Valid
    : code == ClearError   ? ClearError
    : code == UnclearError ? UnclearError
                           : Crash;
}

void WriteFile(const std::string& path, const std::string& text)
{
  std::ofstream(path, std::ios::binary) << text;
}

struct Options
{
  long long Cases = 300;
  long long Start = 0;
  double Timeout = 20.0;
  std::string Keep;
};

Options ParseOptions(int argc, char* argv[])
{
  Options o;
  for (int i = 1; i + 1 < argc; ++i)
  {
    const std::string a = argv[i];
    if (a == "--cases")
    {
      o.Cases = std::atoll(argv[++i]);
    }
    else if (a == "--start")
    {
      o.Start = std::atoll(argv[++i]);
    }
    else if (a == "--timeout")
    {
      o.Timeout = std::atof(argv[++i]);
    }
    else if (a == "--keep")
    {
      o.Keep = argv[++i];
    }
  }
  return o;
}

// Writes case `index` (its scene and mesh) into `dir`; returns the scene path and says how it
// was made.
std::string MakeCase(
  long long index, const std::string& dir, const std::vector<MeshStart>& meshes, std::string& how)
{
  Rng rng(0x9e3779b97f4a7c15ull ^ static_cast<std::uint64_t>(index) * 0xbf58476d1ce4e5b9ull);
  const MeshStart& start = meshes[Pick(rng, meshes.size())];
  const std::string mesh = "mesh" + std::string(start.Extension);
  std::string meshText = start.Text;
  json scene = SceneStart(static_cast<int>(Pick(rng, 2)));
  SetMesh(scene, mesh);
  std::string sceneText;
  how = std::string("mesh start ") + start.Extension + (start.Binary ? " (binary)" : "") + ": ";
  const size_t mutations = 1 + Pick(rng, 3);
  if (Pick(rng, 2) == 0)
  {
    for (size_t k = 0; k < mutations; ++k)
    {
      meshText = MutateText(meshText, rng, start.Binary, how);
    }
    sceneText = scene.dump(1);
  }
  else
  {
    for (size_t k = 0; k < mutations; ++k)
    {
      MutateJson(scene, rng, how);
    }
    sceneText = scene.dump(1);
    if (Pick(rng, 3) == 0)
    {
      // Text mutations of the JSON itself: truncation, junk, NaN/Infinity literals.
      auto tokens = NumberTokens(sceneText);
      if (!tokens.empty() && Pick(rng, 2) == 0)
      {
        const auto t = tokens[Pick(rng, tokens.size())];
        const char* literals[] = { "NaN", "Infinity", "-Infinity", "1e999", "-1e999", "nan" };
        const std::string lit = literals[Pick(rng, 6)];
        how += "; JSON number -> " + lit;
        sceneText.replace(t.first, t.second, lit);
      }
      else
      {
        sceneText = MutateText(sceneText, rng, false, how);
      }
    }
  }
  WriteFile(dir + "/" + mesh, meshText);
  const std::string scenePath = dir + "/scene.json";
  WriteFile(scenePath, sceneText);
  return scenePath;
}
}

int TestSceneFuzz(int argc, char* argv[])
{
  const Options options = ParseOptions(argc, argv);
  char dirTemplate[] = "/tmp/penumbra-fuzz-XXXXXX";
  const char* dir = mkdtemp(dirTemplate);
  CHECK(dir != nullptr);
  const std::vector<MeshStart> meshes = MeshStarts();
  std::map<int, long long> counts;
  long long failures = 0;
  const auto start = std::chrono::steady_clock::now();
  for (long long i = options.Start; i < options.Start + options.Cases; ++i)
  {
    std::string how;
    const std::string scene = MakeCase(i, dir, meshes, how);
    const Outcome outcome = RunCase(scene, options.Timeout);
    ++counts[outcome];
    if (outcome == Crash || outcome == Hang || outcome == UnclearError)
    {
      ++failures;
      const char* what = outcome == Crash ? "CRASH" : outcome == Hang ? "HANG" : "UNCLEAR ERROR";
      std::cout << "case " << i << ": " << what << " (" << how << ")\n";
      if (!options.Keep.empty())
      {
        const std::string keep = options.Keep + "/case-" + std::to_string(i);
        mkdir(options.Keep.c_str(), 0755);
        mkdir(keep.c_str(), 0755);
        std::string ignored;
        MakeCase(i, keep, meshes, ignored);
      }
    }
  }
  const double seconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "fuzz cases " << options.Start << ".." << options.Start + options.Cases - 1 << ": "
            << counts[Valid] << " valid, " << counts[ClearError] << " clear errors, "
            << counts[UnclearError] << " unclear errors, " << counts[Crash] << " crashes, "
            << counts[Hang] << " hangs, in " << seconds << " s\n";
  std::string cleanup = std::string("rm -rf '") + dir + "'";
  CHECK(std::system(cleanup.c_str()) == 0);
  CHECK(failures == 0);
  // The mutations must reach both outcomes, or the run tests nothing.
  CHECK(options.Cases < 50 || (counts[Valid] > 0 && counts[ClearError] > 0));
  return EXIT_SUCCESS;
}
