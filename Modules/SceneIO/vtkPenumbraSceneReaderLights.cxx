// vtkPenumbraSceneReader: the scene's lights, of every type, and what every light has.

#include "vtkPenumbraSceneReaderInternals.h"

#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraGoniometricLight.h"
#include "vtkPenumbraShadowKeys.h"

#include <algorithm>

using namespace penumbra_scene_io;

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
    keys({ "position", "focal_point", "cone_angle", "exponent", "radius" });
  }
  else
  {
    keys({ "position", "radius" });
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
  // A sphere light: shadowed as its disc facing the focal point (straight down for a point).
  const double radius = ctx.Number(obj, field, "radius", 0.0);
  if (!(radius >= 0.0) || !std::isfinite(radius))
  {
    ctx.Fail(Ctx::Sub(field, "radius"), "light radius must be a finite length >= 0");
  }
  vtkPenumbraShadowKeys::SetLightRadius(light, radius);
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

// A rectangular, linear or disc emitter (vtkPenumbraAreaLight): its size, emission direction and
// axes.
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
  else if (type == "disc")
  {
    keys({ "position", "focal_point", "normal", "radius", "samples" });
    pos = ctx.Vector(obj, field, "position", 3, {}, true);
    const double radius = ctx.Number(obj, field, "radius", 0.0, true);
    if (!(radius > 0.0) || !std::isfinite(radius))
    {
      ctx.Fail(Ctx::Sub(field, "radius"), "disc light radius must be positive");
    }
    area->SetShapeToDisc();
    area->SetWidth(2.0 * radius);
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
  else if (type == "area" || type == "linear" || type == "disc")
  {
    light = this->AreaLight(ctx, obj, field, type, keys);
  }
  else
  {
    ctx.Fail(Ctx::Sub(field, "type"),
      "unknown light type " + Quote(type) +
        " (expected directional, spot, point, goniometric, area, linear or disc)");
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
