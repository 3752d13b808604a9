/**
 * @file   vtkPenumbraSceneReaderInternals.h
 * @brief  The state of a vtkPenumbraSceneReader shared by its files and the validation context
 *         every part of a scene is read through: the scene as a whole
 *         (vtkPenumbraSceneReader.cxx), its objects, files and generators
 *         (vtkPenumbraSceneReaderObjects.cxx), its lights (vtkPenumbraSceneReaderLights.cxx) and
 *         its up axis and camera (vtkPenumbraSceneReaderCamera.cxx). Private to the module.
 */

#ifndef vtkPenumbraSceneReaderInternals_h
#define vtkPenumbraSceneReaderInternals_h

#include "vtkPenumbraSceneReader.h"

#include "vtkActor.h"
#include "vtkLight.h"
#include "vtkPolyData.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtksys/SystemTools.hxx"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

class vtkAlgorithm;

#ifndef PENUMBRA_DEFAULT_DATA_DIR
#define PENUMBRA_DEFAULT_DATA_DIR ""
#endif

namespace penumbra_scene_io
{
using json = nlohmann::json;

struct SceneError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

inline std::string Quote(const std::string& s)
{
  return "\"" + s + "\"";
}

inline std::string JoinKeys(const std::vector<std::string>& keys)
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

inline bool NonZero(const std::vector<double>& v)
{
  return std::fabs(v[0]) + std::fabs(v[1]) + std::fabs(v[2]) > 0.0;
}

// Defined with the camera (vtkPenumbraSceneReaderCamera.cxx), used by the lights too.
void FromZUp(const double up[3], double v[3]);
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
  std::string CasterExchange = "need";
  double CasterMemoryBudget = 0.0; // MiB per rank, 0: none
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

  vtkSmartPointer<vtkPolyData> RunAlgorithm(const penumbra_scene_io::Ctx& ctx,
    const std::string& field, vtkAlgorithm* alg, const std::string& what) const;
  vtkSmartPointer<vtkPolyData> LoadFile(const penumbra_scene_io::Ctx& ctx, const std::string& field,
    const penumbra_scene_io::json& obj, const char* dataDir) const;
  vtkSmartPointer<vtkPolyData> Generate(const penumbra_scene_io::Ctx& ctx, const std::string& field,
    const penumbra_scene_io::json& gen, const char* dataDir) const;
  void BuildObject(const penumbra_scene_io::Ctx& ctx, const penumbra_scene_io::json& obj,
    size_t index, const char* dataDir);
  void BuildLight(
    const penumbra_scene_io::Ctx& ctx, const penumbra_scene_io::json& obj, size_t index);
  // The light types' parts of BuildLight; `keys` checks the entry's keys (with the common ones).
  using KeyCheck = std::function<void(std::vector<std::string>)>;
  vtkSmartPointer<vtkLight> DirectionalLight(const penumbra_scene_io::Ctx& ctx,
    const penumbra_scene_io::json& obj, const std::string& field, const std::string& type,
    const KeyCheck& keys);
  vtkSmartPointer<vtkLight> PositionalLight(const penumbra_scene_io::Ctx& ctx,
    const penumbra_scene_io::json& obj, const std::string& field, const std::string& type,
    const KeyCheck& keys);
  vtkSmartPointer<vtkLight> GoniometricLight(const penumbra_scene_io::Ctx& ctx,
    const penumbra_scene_io::json& obj, const std::string& field, const std::string& type,
    const KeyCheck& keys);
  vtkSmartPointer<vtkLight> AreaLight(const penumbra_scene_io::Ctx& ctx,
    const penumbra_scene_io::json& obj, const std::string& field, const std::string& type,
    const KeyCheck& keys);
  void ReadUp(const penumbra_scene_io::Ctx& ctx, const penumbra_scene_io::json& root);
  void BuildCamera(const penumbra_scene_io::Ctx& ctx, const penumbra_scene_io::json& cam);
  void ReadSettings(const penumbra_scene_io::Ctx& ctx, const penumbra_scene_io::json& root);
  void ReadDistributed(const penumbra_scene_io::Ctx& ctx, const penumbra_scene_io::json& root);
  void Build(const penumbra_scene_io::Ctx& ctx, const penumbra_scene_io::json& root,
    const char* dataDir, bool settingsOnly);
};

#endif
// VTK-HeaderTest-Exclude: vtkPenumbraSceneReaderInternals.h
