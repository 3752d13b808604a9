// vtkPenumbraSceneReader: the scene's objects, each a mesh file or a generator, with its
// transform and appearance.

#include "vtkPenumbraSceneReaderInternals.h"

#include "vtkAlgorithm.h"
#include "vtkCallbackCommand.h"
#include "vtkCityGMLReader.h"
#include "vtkCommand.h"
#include "vtkCompositeDataGeometryFilter.h"
#include "vtkCubeSource.h"
#include "vtkDataSet.h"
#include "vtkDataSetSurfaceFilter.h"
#include "vtkGenericDataObjectReader.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkOBJReader.h"
#include "vtkPLYReader.h"
#include "vtkPenumbraCityBlockSource.h"
#include "vtkPenumbraIsosurfaceSource.h"
#include "vtkPenumbraMeshFileCheck.h"
#include "vtkPenumbraRoomSource.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPenumbraTerrainSource.h"
#include "vtkPlaneSource.h"
#include "vtkPoints.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkSTLReader.h"
#include "vtkSphereSource.h"
#include "vtkTransform.h"
#include "vtkTriangleFilter.h"
#include "vtkXMLPolyDataReader.h"
#include "vtkXMLUnstructuredGridReader.h"

#include <map>

using namespace penumbra_scene_io;

namespace
{
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

template <class Reader>
vtkSmartPointer<vtkAlgorithm> MakeReader(const std::string& path)
{
  auto reader = vtkSmartPointer<Reader>::New();
  reader->SetFileName(path.c_str());
  return reader;
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
