#include "vtkPenumbraSceneReader.h"

#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraCityBlockSource.h"
#include "vtkPenumbraGoniometricLight.h"
#include "vtkPenumbraIsosurfaceSource.h"
#include "vtkPenumbraMeshFileCheck.h"
#include "vtkPenumbraRoomSource.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPenumbraTerrainSource.h"

#include "vtkActor.h"
#include "vtkAlgorithm.h"
#include "vtkCallbackCommand.h"
#include "vtkCamera.h"
#include "vtkCityGMLReader.h"
#include "vtkCommand.h"
#include "vtkCompositeDataGeometryFilter.h"
#include "vtkCubeSource.h"
#include "vtkDataArray.h"
#include "vtkDataSet.h"
#include "vtkDataSetSurfaceFilter.h"
#include "vtkGenericDataObjectReader.h"
#include "vtkLight.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkOBJReader.h"
#include "vtkObjectFactory.h"
#include "vtkPLYReader.h"
#include "vtkPlaneSource.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderer.h"
#include "vtkSTLReader.h"
#include "vtkSmartPointer.h"
#include "vtkSphereSource.h"
#include "vtkTransform.h"
#include "vtkTriangleFilter.h"
#include "vtkXMLPolyDataReader.h"
#include "vtkXMLUnstructuredGridReader.h"
#include "vtksys/SystemTools.hxx"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#ifndef PENUMBRA_DEFAULT_DATA_DIR
#define PENUMBRA_DEFAULT_DATA_DIR ""
#endif

using json = nlohmann::json;

namespace
{
struct SceneError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

// Collects the first error a VTK algorithm reports instead of letting it print.
struct ErrorCatcher
{
  std::string Message;
  vtkNew<vtkCallbackCommand> Command;
  ErrorCatcher()
  {
    this->Command->SetClientData(this);
    this->Command->SetCallback(
      [](vtkObject*, unsigned long, void* self, void* data)
      {
        auto* catcher = static_cast<ErrorCatcher*>(self);
        if (catcher->Message.empty() && data)
        {
          catcher->Message = static_cast<const char*>(data);
          while (!catcher->Message.empty() &&
            (catcher->Message.back() == '\n' || catcher->Message.back() == ' '))
          {
            catcher->Message.pop_back();
          }
        }
      });
  }
  void Watch(vtkObject* obj)
  {
    obj->AddObserver(vtkCommand::ErrorEvent, this->Command);
    obj->AddObserver(vtkCommand::WarningEvent, vtkNew<vtkCallbackCommand>());
  }
};

std::string Quote(const std::string& s)
{
  return "\"" + s + "\"";
}

std::string JoinKeys(const std::vector<std::string>& keys)
{
  std::string out;
  for (size_t i = 0; i < keys.size(); ++i)
  {
    out += (i ? ", " : "") + keys[i];
  }
  return out;
}

// Validation context: every accessor knows the field path it reads, so each message names
// the file, the field and the problem.
class Ctx
{
public:
  explicit Ctx(std::string label)
    : Label(std::move(label))
  {
  }

  [[noreturn]] void Fail(const std::string& field, const std::string& what) const
  {
    throw SceneError(this->Label + ": " + (field.empty() ? "" : field + ": ") + what);
  }

  static std::string Sub(const std::string& field, const std::string& key)
  {
    return field.empty() ? key : field + "." + key;
  }

  void Keys(
    const json& obj, const std::string& field, const std::vector<std::string>& allowed) const
  {
    if (!obj.is_object())
    {
      this->Fail(field, "expected an object");
    }
    for (auto it = obj.begin(); it != obj.end(); ++it)
    {
      bool known = false;
      for (const auto& k : allowed)
      {
        known = known || (k == it.key());
      }
      if (!known)
      {
        this->Fail(Sub(field, it.key()), "unknown key (allowed here: " + JoinKeys(allowed) + ")");
      }
    }
  }

  double Number(const json& obj, const std::string& field, const std::string& key, double def,
    bool required = false) const
  {
    const std::string f = Sub(field, key);
    if (!obj.contains(key))
    {
      if (required)
      {
        this->Fail(f, "missing (a number is required)");
      }
      return def;
    }
    return this->Value(obj.at(key), f);
  }

  double Value(const json& v, const std::string& f) const
  {
    if (!v.is_number())
    {
      this->Fail(f, "expected a number, got " + v.dump());
    }
    const double d = v.get<double>();
    if (!std::isfinite(d))
    {
      this->Fail(f, "must be a finite number, got " + v.dump());
    }
    return d;
  }

  double Positive(const json& obj, const std::string& field, const std::string& key, double def,
    bool required = false) const
  {
    const double d = this->Number(obj, field, key, def, required);
    if (!(d > 0.0))
    {
      this->Fail(Sub(field, key), "must be positive, got " + std::to_string(d));
    }
    return d;
  }

  int Integer(const json& obj, const std::string& field, const std::string& key, int def, int lo,
    int hi) const
  {
    const std::string f = Sub(field, key);
    if (!obj.contains(key))
    {
      return def;
    }
    const json& v = obj.at(key);
    if (!v.is_number_integer())
    {
      this->Fail(f, "expected an integer, got " + v.dump());
    }
    const long long i = v.get<long long>();
    if (i < lo || i > hi)
    {
      this->Fail(f,
        "must be between " + std::to_string(lo) + " and " + std::to_string(hi) + ", got " +
          std::to_string(i));
    }
    return static_cast<int>(i);
  }

  bool Bool(const json& obj, const std::string& field, const std::string& key, bool def) const
  {
    if (!obj.contains(key))
    {
      return def;
    }
    if (!obj.at(key).is_boolean())
    {
      this->Fail(Sub(field, key), "expected true or false, got " + obj.at(key).dump());
    }
    return obj.at(key).get<bool>();
  }

  std::string String(const json& obj, const std::string& field, const std::string& key,
    const std::string& def, bool required = false) const
  {
    const std::string f = Sub(field, key);
    if (!obj.contains(key))
    {
      if (required)
      {
        this->Fail(f, "missing (a string is required)");
      }
      return def;
    }
    if (!obj.at(key).is_string())
    {
      this->Fail(f, "expected a string, got " + obj.at(key).dump());
    }
    return obj.at(key).get<std::string>();
  }

  std::vector<double> Vector(const json& obj, const std::string& field, const std::string& key,
    size_t n, const std::vector<double>& def, bool required = false) const
  {
    const std::string f = Sub(field, key);
    if (!obj.contains(key))
    {
      if (required)
      {
        this->Fail(f, "missing (a list of " + std::to_string(n) + " numbers is required)");
      }
      return def;
    }
    const json& v = obj.at(key);
    if (!v.is_array() || v.size() != n)
    {
      this->Fail(f, "expected a list of " + std::to_string(n) + " numbers, got " + v.dump());
    }
    std::vector<double> out;
    for (size_t i = 0; i < n; ++i)
    {
      out.push_back(this->Value(v[i], f + "[" + std::to_string(i) + "]"));
    }
    return out;
  }

  std::vector<double> Color(const json& obj, const std::string& field, const std::string& key,
    const std::vector<double>& def) const
  {
    auto c = this->Vector(obj, field, key, 3, def);
    for (double x : c)
    {
      if (x < 0.0 || x > 1.0)
      {
        this->Fail(Sub(field, key), "colour components must be in [0, 1]");
      }
    }
    return c;
  }

  std::string Label;
};

template <class Reader>
vtkSmartPointer<vtkAlgorithm> MakeReader(const std::string& path)
{
  auto reader = vtkSmartPointer<Reader>::New();
  reader->SetFileName(path.c_str());
  return reader;
}

bool NonZero(const std::vector<double>& v)
{
  return std::fabs(v[0]) + std::fabs(v[1]) + std::fabs(v[2]) > 0.0;
}

// Turns `v`, given in a z-up frame, into the scene's frame whose up axis is `up` (unit): the
// shortest rotation taking +z to `up` (Rodrigues' formula about z x up), a half turn about
// +x when `up` is -z. So for "up": "y", north (+y of the z-up frame) becomes -z and east stays
// +x, the usual mapping of geographic axes onto a y-up mesh (e.g. glTF).
void FromZUp(const double up[3], double v[3])
{
  const double c = up[2];                  // cos of the angle between +z and up
  double axis[3] = { -up[1], up[0], 0.0 }; // z x up
  const double s = vtkMath::Normalize(axis);
  if (s < 1e-12)
  {
    if (c < 0) // half turn about +x
    {
      v[1] = -v[1];
      v[2] = -v[2];
    }
    return;
  }
  double cross[3];
  vtkMath::Cross(axis, v, cross);
  const double dot = vtkMath::Dot(axis, v);
  for (int i = 0; i < 3; ++i)
  {
    v[i] = v[i] * c + cross[i] * s + axis[i] * dot * (1.0 - c);
  }
}

vtkIdType CountNonFinite(vtkPolyData* pd)
{
  vtkIdType bad = 0;
  vtkPoints* pts = pd->GetPoints();
  if (!pts)
  {
    return 0;
  }
  for (vtkIdType i = 0; i < pts->GetNumberOfPoints(); ++i)
  {
    double p[3];
    pts->GetPoint(i, p);
    bad += (std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])) ? 0 : 1;
  }
  return bad;
}
}

struct vtkPenumbraSceneReader::Internals
{
  std::string Error;
  std::string Label;
  std::string BaseDirectory;
  vtkSmartPointer<vtkRenderer> Renderer;
  int Width = 640;
  int Height = 480;
  // The scene's up axis (unit): the sun's elevation and azimuth and the default camera are
  // relative to it.
  double Up[3] = { 0, 0, 1 };
  std::string TechniqueName = "auto";
  std::string TechniqueOptions = "{}";
  std::vector<std::string> ObjectNames;
  std::vector<vtkSmartPointer<vtkActor>> Actors;

  std::string DataDirectory(const char* configured) const
  {
    if (configured && *configured)
    {
      return configured;
    }
    if (const char* env = std::getenv("PENUMBRA_DATA_DIR"))
    {
      if (*env)
      {
        return env;
      }
    }
    return PENUMBRA_DEFAULT_DATA_DIR;
  }

  std::string Resolve(const std::string& path, const char* dataDir) const
  {
    if (path.rfind("$DATA/", 0) == 0)
    {
      return this->DataDirectory(dataDir) + "/" + path.substr(6);
    }
    if (vtksys::SystemTools::FileIsFullPath(path) || this->BaseDirectory.empty())
    {
      return path;
    }
    return this->BaseDirectory + "/" + path;
  }

  vtkSmartPointer<vtkPolyData> RunAlgorithm(
    const Ctx& ctx, const std::string& field, vtkAlgorithm* alg, const std::string& what) const;
  vtkSmartPointer<vtkPolyData> LoadFile(
    const Ctx& ctx, const std::string& field, const json& obj, const char* dataDir) const;
  vtkSmartPointer<vtkPolyData> Generate(
    const Ctx& ctx, const std::string& field, const json& gen, const char* dataDir) const;
  void BuildObject(const Ctx& ctx, const json& obj, size_t index, const char* dataDir);
  void BuildLight(const Ctx& ctx, const json& obj, size_t index);
  // The light types' parts of BuildLight; `keys` checks the entry's keys (with the common ones).
  using KeyCheck = std::function<void(std::vector<std::string>)>;
  vtkSmartPointer<vtkLight> DirectionalLight(const Ctx& ctx, const json& obj,
    const std::string& field, const std::string& type, const KeyCheck& keys);
  vtkSmartPointer<vtkLight> PositionalLight(const Ctx& ctx, const json& obj,
    const std::string& field, const std::string& type, const KeyCheck& keys);
  vtkSmartPointer<vtkLight> GoniometricLight(const Ctx& ctx, const json& obj,
    const std::string& field, const std::string& type, const KeyCheck& keys);
  vtkSmartPointer<vtkLight> AreaLight(const Ctx& ctx, const json& obj, const std::string& field,
    const std::string& type, const KeyCheck& keys);
  void ReadUp(const Ctx& ctx, const json& root);
  void BuildCamera(const Ctx& ctx, const json& cam);
  void Build(const Ctx& ctx, const json& root, const char* dataDir);
};

vtkSmartPointer<vtkPolyData> vtkPenumbraSceneReader::Internals::RunAlgorithm(
  const Ctx& ctx, const std::string& field, vtkAlgorithm* alg, const std::string& what) const
{
  ErrorCatcher errors;
  errors.Watch(alg);
  alg->Update();
  if (!errors.Message.empty())
  {
    // VTK messages start with "In file:line\nClass (0x..): "; keep the last line.
    std::string msg = errors.Message;
    const size_t nl = msg.rfind('\n');
    if (nl != std::string::npos)
    {
      msg = msg.substr(nl + 1);
    }
    const size_t colon = msg.find("): ");
    if (colon != std::string::npos)
    {
      msg = msg.substr(colon + 3);
    }
    ctx.Fail(field, what + " failed: " + msg);
  }
  vtkDataObject* out = alg->GetOutputDataObject(0);
  // Readers pass cell point ids on as the file gives them; one past the points crashes the
  // filters and the renderer later, far from the file that caused it.
  const std::string badCells =
    vtkPenumbraMeshFileCheck::CheckConnectivity(vtkDataSet::SafeDownCast(out));
  if (!badCells.empty())
  {
    ctx.Fail(field, what + " failed: " + badCells);
  }
  vtkSmartPointer<vtkPolyData> pd = vtkPolyData::SafeDownCast(out);
  if (!pd)
  {
    vtkNew<vtkDataSetSurfaceFilter> surface;
    surface->SetInputData(out);
    surface->Update();
    pd = surface->GetOutput();
  }
  vtkSmartPointer<vtkPolyData> copy = vtkSmartPointer<vtkPolyData>::New();
  copy->ShallowCopy(pd);
  if (copy->GetNumberOfPolys() + copy->GetNumberOfStrips() == 0)
  {
    ctx.Fail(field, what + " produced no surface (no polygons)");
  }
  const vtkIdType bad = CountNonFinite(copy);
  if (bad > 0)
  {
    ctx.Fail(
      field, what + " has " + std::to_string(bad) + " point(s) with NaN or infinite coordinates");
  }
  return copy;
}

vtkSmartPointer<vtkPolyData> vtkPenumbraSceneReader::Internals::LoadFile(
  const Ctx& ctx, const std::string& field, const json& obj, const char* dataDir) const
{
  const std::string f = Ctx::Sub(field, "file");
  const std::string given = ctx.String(obj, field, "file", "", true);
  const std::string path = this->Resolve(given, dataDir);
  if (!vtksys::SystemTools::FileExists(path, true))
  {
    ctx.Fail(f, "file not found: " + path);
  }
  const std::string ext =
    vtksys::SystemTools::LowerCase(vtksys::SystemTools::GetFilenameLastExtension(path));
  const std::string what = "reading " + path;
  if (obj.contains("lod") && ext != ".gml")
  {
    ctx.Fail(Ctx::Sub(field, "lod"), "only CityGML (.gml) files have levels of detail");
  }
  using ReaderFactory = vtkSmartPointer<vtkAlgorithm> (*)(const std::string&);
  static const std::map<std::string, ReaderFactory> readers = {
    { ".vtp", MakeReader<vtkXMLPolyDataReader> },
    { ".vtu", MakeReader<vtkXMLUnstructuredGridReader> },
    { ".vtk", MakeReader<vtkGenericDataObjectReader> },
    { ".ply", MakeReader<vtkPLYReader> },
    { ".obj", MakeReader<vtkOBJReader> },
    { ".stl", MakeReader<vtkSTLReader> },
  };
  auto reader = readers.find(ext);
  if (reader != readers.end())
  {
    // VTK 9.1's PLY and OBJ readers trust the file; check its structure first.
    vtkNew<vtkPenumbraMeshFileCheck> check;
    check->SetFileName(path.c_str());
    if (!check->Check())
    {
      ctx.Fail(f, path + ": " + check->GetErrorMessage());
    }
    vtkSmartPointer<vtkAlgorithm> alg = reader->second(path);
    return this->RunAlgorithm(ctx, f, alg, what);
  }
  if (ext == ".gml")
  {
    // Without an explicit LOD, take the most detailed one the file has.
    const int requested = ctx.Integer(obj, field, "lod", -1, 0, 4);
    std::vector<int> lods;
    if (requested >= 0)
    {
      lods.push_back(requested);
    }
    else
    {
      lods = { 4, 3, 2, 1, 0 };
    }
    for (int lod : lods)
    {
      vtkNew<vtkCityGMLReader> r;
      r->SetFileName(path.c_str());
      r->SetLOD(lod);
      vtkNew<vtkCompositeDataGeometryFilter> merge;
      merge->SetInputConnection(r->GetOutputPort());
      ErrorCatcher errors;
      errors.Watch(r);
      errors.Watch(merge);
      merge->Update();
      if (!errors.Message.empty())
      {
        ctx.Fail(f, what + " failed");
      }
      if (merge->GetOutput()->GetNumberOfPolys() > 0)
      {
        return this->RunAlgorithm(ctx, f, merge, what + " (LOD " + std::to_string(lod) + ")");
      }
    }
    ctx.Fail(requested >= 0 ? Ctx::Sub(field, "lod") : f,
      path + " has no geometry" +
        (requested >= 0 ? " at LOD " + std::to_string(requested) : std::string(" at any LOD")));
  }
  ctx.Fail(
    f, "unsupported file type " + Quote(ext) + " (expected .vtp .vtk .vtu .ply .obj .stl .gml)");
}

vtkSmartPointer<vtkPolyData> vtkPenumbraSceneReader::Internals::Generate(
  const Ctx& ctx, const std::string& field, const json& gen, const char* dataDir) const
{
  if (!gen.is_object())
  {
    ctx.Fail(field, "expected an object with a \"type\"");
  }
  const std::string type = ctx.String(gen, field, "type", "", true);
  const std::string what = type + " generator";
  if (type == "plane")
  {
    ctx.Keys(gen, field, { "type", "origin", "point1", "point2", "resolution" });
    auto o = ctx.Vector(gen, field, "origin", 3, { -1, -1, 0 });
    auto p1 = ctx.Vector(gen, field, "point1", 3, { 1, -1, 0 });
    auto p2 = ctx.Vector(gen, field, "point2", 3, { -1, 1, 0 });
    const int res = ctx.Integer(gen, field, "resolution", 1, 1, 4096);
    vtkNew<vtkPlaneSource> s;
    s->SetOrigin(o.data());
    s->SetPoint1(p1.data());
    s->SetPoint2(p2.data());
    s->SetResolution(res, res);
    return this->RunAlgorithm(ctx, field, s, what);
  }
  if (type == "box")
  {
    ctx.Keys(gen, field, { "type", "bounds" });
    auto b = ctx.Vector(gen, field, "bounds", 6, {}, true);
    if (!(b[1] >= b[0] && b[3] >= b[2] && b[5] >= b[4]))
    {
      ctx.Fail(
        Ctx::Sub(field, "bounds"), "expected [xmin, xmax, ymin, ymax, zmin, zmax] with min <= max");
    }
    vtkNew<vtkCubeSource> s;
    s->SetBounds(b.data());
    vtkNew<vtkTriangleFilter> tri;
    tri->SetInputConnection(s->GetOutputPort());
    return this->RunAlgorithm(ctx, field, tri, what);
  }
  if (type == "sphere")
  {
    ctx.Keys(gen, field, { "type", "center", "radius", "resolution" });
    auto c = ctx.Vector(gen, field, "center", 3, { 0, 0, 0 });
    const double r = ctx.Positive(gen, field, "radius", 1.0);
    const int res = ctx.Integer(gen, field, "resolution", 32, 3, 1024);
    vtkNew<vtkSphereSource> s;
    s->SetCenter(c.data());
    s->SetRadius(r);
    s->SetThetaResolution(res);
    s->SetPhiResolution(res);
    return this->RunAlgorithm(ctx, field, s, what);
  }
  if (type == "city_block")
  {
    ctx.Keys(gen, field,
      { "type", "rows", "columns", "spacing", "footprint_min", "footprint_max", "min_height",
        "max_height", "seed", "offset", "ground", "ground_margin", "gable_roof_fraction",
        "gable_roof_pitch" });
    vtkNew<vtkPenumbraCityBlockSource> s;
    s->SetRows(ctx.Integer(gen, field, "rows", s->GetRows(), 1, 1000));
    s->SetColumns(ctx.Integer(gen, field, "columns", s->GetColumns(), 1, 1000));
    s->SetSpacing(ctx.Positive(gen, field, "spacing", s->GetSpacing()));
    s->SetFootprintMin(ctx.Positive(gen, field, "footprint_min", s->GetFootprintMin()));
    s->SetFootprintMax(ctx.Positive(gen, field, "footprint_max", s->GetFootprintMax()));
    s->SetMinHeight(ctx.Positive(gen, field, "min_height", s->GetMinHeight()));
    s->SetMaxHeight(ctx.Positive(gen, field, "max_height", s->GetMaxHeight()));
    s->SetSeed(ctx.Integer(gen, field, "seed", s->GetSeed(), 0, 2147483647));
    auto off = ctx.Vector(gen, field, "offset", 3, { 0, 0, 0 });
    s->SetOrigin(off.data());
    s->SetGenerateGround(ctx.Bool(gen, field, "ground", s->GetGenerateGround() != 0));
    s->SetGroundMargin(ctx.Number(gen, field, "ground_margin", s->GetGroundMargin()));
    s->SetGableRoofFraction(
      ctx.Number(gen, field, "gable_roof_fraction", s->GetGableRoofFraction()));
    s->SetGableRoofPitch(ctx.Number(gen, field, "gable_roof_pitch", s->GetGableRoofPitch()));
    return this->RunAlgorithm(ctx, field, s, what);
  }
  if (type == "isosurface")
  {
    ctx.Keys(gen, field, { "type", "file", "iso_value", "resolution", "bounds" });
    vtkNew<vtkPenumbraIsosurfaceSource> s;
    if (gen.contains("file"))
    {
      const std::string path = this->Resolve(ctx.String(gen, field, "file", ""), dataDir);
      if (!vtksys::SystemTools::FileExists(path, true))
      {
        ctx.Fail(Ctx::Sub(field, "file"), "file not found: " + path);
      }
      s->SetFileName(path.c_str());
    }
    s->SetIsoValue(ctx.Number(gen, field, "iso_value", s->GetIsoValue()));
    s->SetResolution(ctx.Integer(gen, field, "resolution", s->GetResolution(), 2, 1024));
    if (gen.contains("bounds"))
    {
      auto b = ctx.Vector(gen, field, "bounds", 6, {});
      s->SetBounds(b.data());
    }
    return this->RunAlgorithm(ctx, field, s, what);
  }
  if (type == "room")
  {
    ctx.Keys(gen, field, { "type", "size", "furniture" });
    vtkNew<vtkPenumbraRoomSource> s;
    double* def = s->GetSize();
    auto size = ctx.Vector(gen, field, "size", 3, { def[0], def[1], def[2] });
    for (double x : size)
    {
      if (!(x > 0.0))
      {
        ctx.Fail(Ctx::Sub(field, "size"), "room dimensions must be positive");
      }
    }
    s->SetSize(size.data());
    s->SetGenerateFurniture(ctx.Bool(gen, field, "furniture", true));
    return this->RunAlgorithm(ctx, field, s, what);
  }
  if (type == "terrain")
  {
    ctx.Keys(gen, field, { "type", "file", "vertical_scale", "sample_rate" });
    vtkNew<vtkPenumbraTerrainSource> s;
    const std::string path = this->Resolve(ctx.String(gen, field, "file", "", true), dataDir);
    if (!vtksys::SystemTools::FileExists(path, true))
    {
      ctx.Fail(Ctx::Sub(field, "file"), "file not found: " + path);
    }
    s->SetFileName(path.c_str());
    s->SetVerticalScale(ctx.Positive(gen, field, "vertical_scale", s->GetVerticalScale()));
    s->SetSampleRate(ctx.Integer(gen, field, "sample_rate", s->GetSampleRate(), 1, 1024));
    return this->RunAlgorithm(ctx, field, s, what);
  }
  ctx.Fail(Ctx::Sub(field, "type"),
    "unknown generator " + Quote(type) +
      " (expected plane, box, sphere, city_block, isosurface, room or terrain)");
}

void vtkPenumbraSceneReader::Internals::BuildObject(
  const Ctx& ctx, const json& obj, size_t index, const char* dataDir)
{
  const std::string field = "objects[" + std::to_string(index) + "]";
  ctx.Keys(obj, field,
    { "name", "file", "lod", "generator", "transform", "color", "opacity", "material",
      "cast_shadows", "receive_shadows", "visible" });
  const bool hasFile = obj.contains("file");
  const bool hasGenerator = obj.contains("generator");
  if (hasFile == hasGenerator)
  {
    ctx.Fail(field, "needs exactly one of \"file\" or \"generator\"");
  }
  const std::string name = ctx.String(obj, field, "name", "object" + std::to_string(index));
  vtkSmartPointer<vtkPolyData> pd = hasFile
    ? this->LoadFile(ctx, field, obj, dataDir)
    : this->Generate(ctx, Ctx::Sub(field, "generator"), obj.at("generator"), dataDir);

  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(pd);
  mapper->ScalarVisibilityOff();
  vtkSmartPointer<vtkActor> actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);

  if (obj.contains("transform"))
  {
    const std::string tf = Ctx::Sub(field, "transform");
    const json& t = obj.at("transform");
    ctx.Keys(t, tf, { "matrix", "translate", "rotate", "scale" });
    vtkNew<vtkTransform> xf;
    xf->PostMultiply();
    if (t.contains("matrix"))
    {
      if (t.size() != 1)
      {
        ctx.Fail(tf, "\"matrix\" cannot be combined with translate/rotate/scale");
      }
      auto m = ctx.Vector(t, tf, "matrix", 16, {});
      xf->SetMatrix(m.data());
      if (std::fabs(xf->GetMatrix()->Determinant()) < 1e-300)
      {
        ctx.Fail(Ctx::Sub(tf, "matrix"), "is singular");
      }
    }
    if (t.contains("scale"))
    {
      std::vector<double> s;
      if (t.at("scale").is_number())
      {
        const double u = ctx.Value(t.at("scale"), Ctx::Sub(tf, "scale"));
        s = { u, u, u };
      }
      else
      {
        s = ctx.Vector(t, tf, "scale", 3, {});
      }
      if (s[0] == 0.0 || s[1] == 0.0 || s[2] == 0.0)
      {
        ctx.Fail(Ctx::Sub(tf, "scale"), "scale factors must be non-zero");
      }
      xf->Scale(s.data());
    }
    if (t.contains("rotate"))
    {
      auto r = ctx.Vector(t, tf, "rotate", 4, {});
      if (!NonZero({ r[1], r[2], r[3] }))
      {
        ctx.Fail(Ctx::Sub(tf, "rotate"),
          "expected [angle_degrees, axis_x, axis_y, axis_z] with a non-zero axis");
      }
      xf->RotateWXYZ(r[0], r[1], r[2], r[3]);
    }
    if (t.contains("translate"))
    {
      auto tr = ctx.Vector(t, tf, "translate", 3, {});
      xf->Translate(tr.data());
    }
    vtkNew<vtkMatrix4x4> m;
    m->DeepCopy(xf->GetMatrix());
    actor->SetUserMatrix(m);
  }

  vtkProperty* prop = actor->GetProperty();
  auto color = ctx.Color(obj, field, "color", { 0.8, 0.8, 0.8 });
  prop->SetColor(color.data());
  const double opacity = ctx.Number(obj, field, "opacity", 1.0);
  if (!(opacity > 0.0 && opacity <= 1.0))
  {
    ctx.Fail(Ctx::Sub(field, "opacity"), "must be in (0, 1]");
  }
  prop->SetOpacity(opacity);
  if (obj.contains("material"))
  {
    const std::string mf = Ctx::Sub(field, "material");
    const json& m = obj.at("material");
    const std::string model = ctx.String(m, mf, "model", "phong");
    auto unit = [&](const char* key, double def)
    {
      const double v = ctx.Number(m, mf, key, def);
      if (v < 0.0 || v > 1.0)
      {
        ctx.Fail(Ctx::Sub(mf, key), "must be in [0, 1]");
      }
      return v;
    };
    if (model == "phong")
    {
      ctx.Keys(m, mf, { "model", "ambient", "diffuse", "specular", "specular_power" });
      prop->SetInterpolationToPhong();
      prop->SetAmbient(unit("ambient", 0.1));
      prop->SetDiffuse(unit("diffuse", 0.9));
      prop->SetSpecular(unit("specular", 0.1));
      prop->SetSpecularPower(ctx.Positive(m, mf, "specular_power", 20.0));
    }
    else if (model == "pbr")
    {
      ctx.Keys(m, mf, { "model", "metallic", "roughness", "ambient" });
      prop->SetInterpolationToPBR();
      prop->SetMetallic(unit("metallic", 0.0));
      prop->SetRoughness(unit("roughness", 0.5));
      prop->SetAmbient(unit("ambient", 0.1));
    }
    else
    {
      ctx.Fail(Ctx::Sub(mf, "model"),
        "unknown material model " + Quote(model) + " (expected phong or pbr)");
    }
  }
  else
  {
    prop->SetAmbient(0.1);
    prop->SetDiffuse(0.9);
    prop->SetSpecular(0.1);
    prop->SetSpecularPower(20.0);
  }
  vtkPenumbraShadowKeys::SetCastsShadows(actor, ctx.Bool(obj, field, "cast_shadows", true));
  vtkPenumbraShadowKeys::SetReceivesShadows(actor, ctx.Bool(obj, field, "receive_shadows", true));
  actor->SetVisibility(ctx.Bool(obj, field, "visible", true));
  // So that extraction errors can say which object is broken.
  vtkPenumbraSceneGeometry::SetPropName(actor, name.c_str());

  this->Renderer->AddActor(actor);
  this->ObjectNames.push_back(name);
  this->Actors.push_back(actor);
}

// "up": an axis name ("x", "y", "z", "-x", "-y", "-z") or a non-zero vector; default "z".
void vtkPenumbraSceneReader::Internals::ReadUp(const Ctx& ctx, const json& root)
{
  this->Up[0] = this->Up[1] = 0.0;
  this->Up[2] = 1.0;
  if (!root.contains("up"))
  {
    return;
  }
  const json& up = root.at("up");
  if (up.is_string())
  {
    const std::string name = up.get<std::string>();
    const std::vector<std::string> axes = { "x", "y", "z", "-x", "-y", "-z" };
    const auto it = std::find(axes.begin(), axes.end(), name);
    if (it == axes.end())
    {
      ctx.Fail("up",
        "expected \"x\", \"y\", \"z\", \"-x\", \"-y\", \"-z\" or a vector [x, y, z], got " +
          Quote(name));
    }
    const int axis = static_cast<int>(it - axes.begin());
    this->Up[2] = 0.0;
    this->Up[axis % 3] = axis < 3 ? 1.0 : -1.0;
    return;
  }
  std::vector<double> v = ctx.Vector(root, "", "up", 3, {});
  if (!NonZero(v))
  {
    ctx.Fail("up", "must be a non-zero vector");
  }
  std::copy(v.begin(), v.end(), this->Up);
  vtkMath::Normalize(this->Up);
}

// A sun: a direction, or elevation and azimuth about the scene's up axis.
vtkSmartPointer<vtkLight> vtkPenumbraSceneReader::Internals::DirectionalLight(const Ctx& ctx,
  const json& obj, const std::string& field, const std::string&, const KeyCheck& keys)
{
  keys({ "direction", "elevation", "azimuth" });
  std::vector<double> dir;
  if (obj.contains("direction"))
  {
    if (obj.contains("elevation") || obj.contains("azimuth"))
    {
      ctx.Fail(field, "give either \"direction\" or \"elevation\"/\"azimuth\", not both");
    }
    dir = ctx.Vector(obj, field, "direction", 3, {});
    if (!NonZero(dir))
    {
      ctx.Fail(Ctx::Sub(field, "direction"), "must be a non-zero vector");
    }
  }
  else
  {
    // Sun convention: azimuth clockwise from north toward east, elevation above the
    // horizon; the light travels from the sun toward the scene. For the default z-up scene
    // north is +y, east +x and the horizon z = 0; another "up" turns them (FromZUp).
    const double el = vtkMath::RadiansFromDegrees(ctx.Number(obj, field, "elevation", 45.0));
    const double az = vtkMath::RadiansFromDegrees(ctx.Number(obj, field, "azimuth", 135.0));
    double d[3] = { -std::cos(el) * std::sin(az), -std::cos(el) * std::cos(az), -std::sin(el) };
    FromZUp(this->Up, d);
    dir = { d[0], d[1], d[2] };
  }
  auto light = vtkSmartPointer<vtkLight>::New();
  light->SetPositional(false);
  light->SetFocalPoint(0, 0, 0);
  light->SetPosition(-dir[0], -dir[1], -dir[2]);
  return light;
}

// A spot light (a cone towards its focal point) or a point light (all directions).
vtkSmartPointer<vtkLight> vtkPenumbraSceneReader::Internals::PositionalLight(const Ctx& ctx,
  const json& obj, const std::string& field, const std::string& type, const KeyCheck& keys)
{
  if (type == "spot")
  {
    keys({ "position", "focal_point", "cone_angle", "exponent" });
  }
  else
  {
    keys({ "position" });
  }
  auto pos = ctx.Vector(obj, field, "position", 3, {}, true);
  auto light = vtkSmartPointer<vtkLight>::New();
  light->SetPositional(true);
  light->SetPosition(pos.data());
  if (type == "spot")
  {
    auto fp = ctx.Vector(obj, field, "focal_point", 3, {}, true);
    if (fp == pos)
    {
      ctx.Fail(Ctx::Sub(field, "focal_point"), "must differ from the position");
    }
    light->SetFocalPoint(fp.data());
    const double cone = ctx.Number(obj, field, "cone_angle", 30.0);
    if (!(cone > 0.0 && cone < 90.0))
    {
      ctx.Fail(Ctx::Sub(field, "cone_angle"),
        "spot cone half-angle must be in (0, 90) degrees; use a point light for all directions");
    }
    light->SetConeAngle(cone);
    light->SetExponent(ctx.Number(obj, field, "exponent", 1.0));
  }
  else
  {
    light->SetFocalPoint(pos[0], pos[1], pos[2] - 1.0);
    light->SetConeAngle(180.0);
  }
  return light;
}

// A point light with a tabulated intensity diagram (vtkPenumbraGoniometricLight).
vtkSmartPointer<vtkLight> vtkPenumbraSceneReader::Internals::GoniometricLight(const Ctx& ctx,
  const json& obj, const std::string& field, const std::string&, const KeyCheck& keys)
{
  // A point light with a tabulated intensity diagram (vtkPenumbraGoniometricLight).
  keys({ "position", "focal_point", "up", "file" });
  auto pos = ctx.Vector(obj, field, "position", 3, {}, true);
  auto fp = ctx.Vector(obj, field, "focal_point", 3, {}, true);
  if (fp == pos)
  {
    ctx.Fail(Ctx::Sub(field, "focal_point"), "must differ from the position");
  }
  auto up = ctx.Vector(obj, field, "up", 3, { 0, 0, 1 });
  if (!NonZero(up))
  {
    ctx.Fail(Ctx::Sub(field, "up"), "must be a non-zero vector");
  }
  auto gonio = vtkSmartPointer<vtkPenumbraGoniometricLight>::New();
  gonio->SetPosition(pos.data());
  gonio->SetFocalPoint(fp.data());
  gonio->SetUp(up.data());
  const std::string path = this->Resolve(ctx.String(obj, field, "file", "", true), nullptr);
  if (!gonio->ReadFile(path.c_str()))
  {
    ctx.Fail(Ctx::Sub(field, "file"), gonio->GetErrorMessage());
  }
  return gonio;
}

// A rectangular or linear emitter (vtkPenumbraAreaLight): its size, emission direction and axes.
vtkSmartPointer<vtkLight> vtkPenumbraSceneReader::Internals::AreaLight(const Ctx& ctx,
  const json& obj, const std::string& field, const std::string& type, const KeyCheck& keys)
{
  auto area = vtkSmartPointer<vtkPenumbraAreaLight>::New();
  std::vector<double> pos;
  if (type == "area")
  {
    keys({ "position", "focal_point", "normal", "size", "up", "samples" });
    pos = ctx.Vector(obj, field, "position", 3, {}, true);
    auto size = ctx.Vector(obj, field, "size", 2, {}, true);
    if (!(size[0] > 0.0 && size[1] > 0.0))
    {
      ctx.Fail(Ctx::Sub(field, "size"), "area light size must be positive in both directions");
    }
    area->SetShapeToRectangle();
    area->SetWidth(size[0]);
    area->SetHeight(size[1]);
    auto up = ctx.Vector(obj, field, "up", 3, { 0, 0, 1 });
    area->SetUp(up.data());
  }
  else
  {
    keys({ "position", "focal_point", "normal", "axis", "length", "samples" });
    pos = ctx.Vector(obj, field, "position", 3, {}, true);
    const double length = ctx.Number(obj, field, "length", 0.0, true);
    if (!(length > 0.0))
    {
      ctx.Fail(Ctx::Sub(field, "length"), "linear light length must be positive");
    }
    area->SetShapeToLine();
    area->SetWidth(length);
  }
  if (obj.contains("focal_point") && obj.contains("normal"))
  {
    ctx.Fail(field, "give either \"focal_point\" or \"normal\", not both");
  }
  std::vector<double> normal = { 0, 0, -1 };
  if (obj.contains("normal"))
  {
    normal = ctx.Vector(obj, field, "normal", 3, {});
  }
  else if (obj.contains("focal_point"))
  {
    auto fp = ctx.Vector(obj, field, "focal_point", 3, {});
    normal = { fp[0] - pos[0], fp[1] - pos[1], fp[2] - pos[2] };
  }
  if (!NonZero(normal))
  {
    ctx.Fail(field, "the emission direction (focal_point - position, or normal) is zero");
  }
  area->SetPosition(pos.data());
  area->SetFocalPoint(pos[0] + normal[0], pos[1] + normal[1], pos[2] + normal[2]);
  if (type == "linear")
  {
    auto axis = ctx.Vector(obj, field, "axis", 3, { 1, 0, 0 });
    double n[3] = { normal[0], normal[1], normal[2] };
    double a[3] = { axis[0], axis[1], axis[2] };
    double up[3];
    vtkMath::Cross(n, a, up); // V = N x U gives U = V x N = the axis
    if (vtkMath::Norm(up) < 1e-12 * vtkMath::Norm(n) * std::max(vtkMath::Norm(a), 1e-300))
    {
      ctx.Fail(
        Ctx::Sub(field, "axis"), "must be non-zero and not parallel to the emission direction");
    }
    area->SetUp(up);
  }
  area->SetSamplesPerAxis(ctx.Integer(obj, field, "samples", 8, 1, 64));
  const std::string why = area->GetValidityMessage();
  if (!why.empty())
  {
    ctx.Fail(field, why);
  }
  return area;
}

// One entry of "lights": the light of its type, then what every light has (colour,
// intensity, switch).
void vtkPenumbraSceneReader::Internals::BuildLight(const Ctx& ctx, const json& obj, size_t index)
{
  const std::string field = "lights[" + std::to_string(index) + "]";
  if (!obj.is_object())
  {
    ctx.Fail(field, "expected an object");
  }
  const std::string type = ctx.String(obj, field, "type", "", true);
  const std::vector<std::string> common = { "type", "color", "intensity", "on" };
  const KeyCheck keys = [&](std::vector<std::string> extra)
  {
    extra.insert(extra.end(), common.begin(), common.end());
    ctx.Keys(obj, field, extra);
  };
  vtkSmartPointer<vtkLight> light;
  if (type == "directional")
  {
    light = this->DirectionalLight(ctx, obj, field, type, keys);
  }
  else if (type == "spot" || type == "point")
  {
    light = this->PositionalLight(ctx, obj, field, type, keys);
  }
  else if (type == "goniometric")
  {
    light = this->GoniometricLight(ctx, obj, field, type, keys);
  }
  else if (type == "area" || type == "linear")
  {
    light = this->AreaLight(ctx, obj, field, type, keys);
  }
  else
  {
    ctx.Fail(Ctx::Sub(field, "type"),
      "unknown light type " + Quote(type) +
        " (expected directional, spot, point, goniometric, area or linear)");
  }
  light->SetLightTypeToSceneLight();
  auto color = ctx.Color(obj, field, "color", { 1, 1, 1 });
  light->SetColor(color.data());
  const double intensity = ctx.Number(obj, field, "intensity", 1.0);
  if (intensity < 0.0)
  {
    ctx.Fail(Ctx::Sub(field, "intensity"), "must not be negative");
  }
  light->SetIntensity(intensity);
  light->SetSwitch(ctx.Bool(obj, field, "on", true) ? 1 : 0);
  this->Renderer->AddLight(light);
}

void vtkPenumbraSceneReader::Internals::BuildCamera(const Ctx& ctx, const json& cam)
{
  const std::string field = "camera";
  ctx.Keys(cam, field,
    { "position", "focal_point", "view_up", "view_angle", "parallel_scale", "clipping_range",
      "auto", "azimuth", "elevation", "zoom" });
  vtkCamera* c = this->Renderer->GetActiveCamera();
  const bool automatic = ctx.Bool(cam, field, "auto", !cam.contains("position"));
  if (!automatic && (cam.contains("azimuth") || cam.contains("elevation") || cam.contains("zoom")))
  {
    ctx.Fail(field, "azimuth/elevation/zoom adjust an automatic camera; set \"auto\": true");
  }
  if (cam.contains("view_angle"))
  {
    const double a = ctx.Number(cam, field, "view_angle", 30.0);
    if (!(a > 0.0 && a < 180.0))
    {
      ctx.Fail("camera.view_angle", "must be in (0, 180) degrees");
    }
    c->SetViewAngle(a);
  }
  if (cam.contains("parallel_scale"))
  {
    c->ParallelProjectionOn();
    c->SetParallelScale(ctx.Positive(cam, field, "parallel_scale", 1.0));
  }
  if (automatic)
  {
    if (cam.contains("view_up") || cam.contains("position") || cam.contains("focal_point"))
    {
      auto pos = ctx.Vector(cam, field, "position", 3, { 0, -1, 1 });
      auto fp = ctx.Vector(cam, field, "focal_point", 3, { 0, 0, 0 });
      auto up = ctx.Vector(cam, field, "view_up", 3, { 0, 0, 1 });
      c->SetPosition(pos.data());
      c->SetFocalPoint(fp.data());
      c->SetViewUp(up.data());
    }
    else
    {
      // Default view from the south-west, slightly above (in the scene's up frame).
      double pos[3] = { -1, -1.5, 1.2 };
      FromZUp(this->Up, pos);
      c->SetPosition(pos);
      c->SetFocalPoint(0, 0, 0);
      c->SetViewUp(this->Up);
    }
    this->Renderer->ResetCamera();
    c->Azimuth(ctx.Number(cam, field, "azimuth", 0.0));
    c->Elevation(ctx.Number(cam, field, "elevation", 0.0));
    c->OrthogonalizeViewUp();
    c->Zoom(ctx.Positive(cam, field, "zoom", 1.0));
  }
  else
  {
    auto pos = ctx.Vector(cam, field, "position", 3, {}, true);
    auto fp = ctx.Vector(cam, field, "focal_point", 3, {}, true);
    auto up = ctx.Vector(cam, field, "view_up", 3, { 0, 0, 1 });
    if (pos == fp)
    {
      ctx.Fail("camera.focal_point", "must differ from the camera position");
    }
    c->SetPosition(pos.data());
    c->SetFocalPoint(fp.data());
    c->SetViewUp(up.data());
    double dop[3];
    c->GetDirectionOfProjection(dop);
    double cross[3];
    vtkMath::Cross(dop, up.data(), cross);
    if (vtkMath::Norm(cross) < 1e-9 * std::max(vtkMath::Norm(up.data()), 1e-300))
    {
      ctx.Fail("camera.view_up", "must not be zero or parallel to the viewing direction");
    }
    c->OrthogonalizeViewUp();
  }
  if (cam.contains("clipping_range"))
  {
    auto r = ctx.Vector(cam, field, "clipping_range", 2, {});
    if (!(r[0] > 0.0 && r[1] > r[0]))
    {
      ctx.Fail("camera.clipping_range", "expected [near, far] with 0 < near < far");
    }
    c->SetClippingRange(r.data());
  }
  else
  {
    this->Renderer->ResetCameraClippingRange();
  }
}

void vtkPenumbraSceneReader::Internals::Build(const Ctx& ctx, const json& root, const char* dataDir)
{
  ctx.Keys(root, "",
    { "description", "image", "background", "up", "camera", "objects", "lights", "technique" });
  if (root.contains("description") && !root.at("description").is_string())
  {
    ctx.Fail("description", "expected a string");
  }
  // Refused before any mesh is read: the scene cannot be rendered as asked.
  if (root.contains("lights") && root.at("lights").is_array() &&
    root.at("lights").size() > static_cast<size_t>(vtkPenumbraSceneReader::MaximumNumberOfLights))
  {
    ctx.Fail("lights",
      std::to_string(root.at("lights").size()) + " lights, at most " +
        std::to_string(vtkPenumbraSceneReader::MaximumNumberOfLights) +
        " are allowed: VTK's lighting shader declares uniforms for every light (OpenGL 4.5 "
        "guarantees 256 fragment uniform vectors) and each shadowed light needs a texture "
        "unit; merge distant lights or use an area light");
  }
  this->Renderer = vtkSmartPointer<vtkRenderer>::New();
  this->Renderer->AutomaticLightCreationOff();
  this->ObjectNames.clear();
  this->Actors.clear();

  if (root.contains("image"))
  {
    const json& img = root.at("image");
    ctx.Keys(img, "image", { "width", "height" });
    this->Width = ctx.Integer(img, "image", "width", 640, 1, 16384);
    this->Height = ctx.Integer(img, "image", "height", 480, 1, 16384);
  }
  auto bg = ctx.Color(root, "", "background", { 0.32, 0.34, 0.43 });
  this->Renderer->SetBackground(bg.data());

  if (!root.contains("objects") || !root.at("objects").is_array())
  {
    ctx.Fail("objects", "missing: a scene needs a list of objects");
  }
  const json& objects = root.at("objects");
  if (objects.empty())
  {
    ctx.Fail("objects", "the scene is empty: add at least one object");
  }
  for (size_t i = 0; i < objects.size(); ++i)
  {
    this->BuildObject(ctx, objects[i], i, dataDir);
  }
  std::set<std::string> names;
  for (size_t i = 0; i < this->ObjectNames.size(); ++i)
  {
    if (!names.insert(this->ObjectNames[i]).second)
    {
      ctx.Fail(
        "objects[" + std::to_string(i) + "].name", "duplicate name " + Quote(this->ObjectNames[i]));
    }
  }

  this->ReadUp(ctx, root);
  if (!root.contains("lights") || !root.at("lights").is_array() || root.at("lights").empty())
  {
    ctx.Fail("lights", "missing: a scene needs a list with at least one light");
  }
  const json& lights = root.at("lights");
  for (size_t i = 0; i < lights.size(); ++i)
  {
    this->BuildLight(ctx, lights[i], i);
  }

  this->BuildCamera(ctx, root.contains("camera") ? root.at("camera") : json::object());

  this->TechniqueName = "auto";
  this->TechniqueOptions = "{}";
  if (root.contains("technique"))
  {
    const json& t = root.at("technique");
    if (!t.is_object())
    {
      ctx.Fail("technique", "expected an object with a \"name\" and options");
    }
    this->TechniqueName = ctx.String(t, "technique", "name", "", true);
    json options = t;
    options.erase("name");
    this->TechniqueOptions = options.dump();
  }
}

vtkStandardNewMacro(vtkPenumbraSceneReader);

vtkPenumbraSceneReader::vtkPenumbraSceneReader()
  : FileName(nullptr)
  , DataDirectory(nullptr)
  , Impl(new Internals)
{
}

vtkPenumbraSceneReader::~vtkPenumbraSceneReader()
{
  this->SetFileName(nullptr);
  this->SetDataDirectory(nullptr);
}

int vtkPenumbraSceneReader::Read()
{
  Internals& impl = *this->Impl;
  if (!this->FileName || !*this->FileName)
  {
    impl.Error = "no scene file name given";
    vtkErrorMacro(<< impl.Error);
    return 0;
  }
  const std::string path = this->FileName;
  std::ifstream in(path);
  if (!in || vtksys::SystemTools::FileIsDirectory(path))
  {
    impl.Error = path + ": cannot open the scene file";
    impl.Renderer = nullptr;
    vtkErrorMacro(<< impl.Error);
    return 0;
  }
  std::stringstream text;
  text << in.rdbuf();
  return this->ReadFromString(text.str().c_str(), path.c_str(),
    vtksys::SystemTools::GetFilenamePath(vtksys::SystemTools::CollapseFullPath(path)).c_str());
}

int vtkPenumbraSceneReader::ReadFromString(
  const char* text, const char* label, const char* baseDirectory)
{
  Internals& impl = *this->Impl;
  impl.Label = label ? label : "<scene>";
  impl.BaseDirectory = baseDirectory ? baseDirectory : "";
  impl.Error.clear();
  const Ctx ctx(impl.Label);
  try
  {
    json root;
    try
    {
      root = json::parse(text ? text : "");
    }
    catch (const json::exception& e)
    {
      // Syntax errors carry line and column; number overflow (1e999) is reported here too.
      std::string what = e.what();
      const size_t tag = what.find("] ");
      throw SceneError(
        impl.Label + ": invalid JSON: " + (tag == std::string::npos ? what : what.substr(tag + 2)));
    }
    if (!root.is_object())
    {
      ctx.Fail("", "the scene must be a JSON object");
    }
    impl.Build(ctx, root, this->DataDirectory);
  }
  catch (const SceneError& e)
  {
    impl.Error = e.what();
  }
  catch (const std::exception& e)
  {
    impl.Error = impl.Label + ": " + e.what();
  }
  if (!impl.Error.empty())
  {
    impl.Renderer = nullptr;
    impl.ObjectNames.clear();
    impl.Actors.clear();
    vtkErrorMacro(<< impl.Error);
    return 0;
  }
  this->Modified();
  return 1;
}

const char* vtkPenumbraSceneReader::GetErrorMessage()
{
  return this->Impl->Error.c_str();
}

vtkRenderer* vtkPenumbraSceneReader::GetRenderer()
{
  return this->Impl->Renderer;
}

int vtkPenumbraSceneReader::GetWidth()
{
  return this->Impl->Width;
}

int vtkPenumbraSceneReader::GetHeight()
{
  return this->Impl->Height;
}

const char* vtkPenumbraSceneReader::GetTechniqueName()
{
  return this->Impl->TechniqueName.c_str();
}

const char* vtkPenumbraSceneReader::GetTechniqueOptions()
{
  return this->Impl->TechniqueOptions.c_str();
}

const char* vtkPenumbraSceneReader::GetSceneLabel()
{
  return this->Impl->Label.c_str();
}

int vtkPenumbraSceneReader::GetNumberOfObjects()
{
  return static_cast<int>(this->Impl->Actors.size());
}

const char* vtkPenumbraSceneReader::GetObjectName(int index)
{
  if (index < 0 || index >= this->GetNumberOfObjects())
  {
    return nullptr;
  }
  return this->Impl->ObjectNames[static_cast<size_t>(index)].c_str();
}

vtkActor* vtkPenumbraSceneReader::GetObjectActor(int index)
{
  if (index < 0 || index >= this->GetNumberOfObjects())
  {
    return nullptr;
  }
  return this->Impl->Actors[static_cast<size_t>(index)];
}

void vtkPenumbraSceneReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "DataDirectory: " << this->Impl->DataDirectory(this->DataDirectory) << "\n";
  os << indent << "Objects: " << this->Impl->Actors.size() << "\n";
  os << indent << "Technique: " << this->Impl->TechniqueName << "\n";
}
