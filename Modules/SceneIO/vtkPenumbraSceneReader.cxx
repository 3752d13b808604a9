#include "vtkPenumbraSceneReader.h"
#include "vtkPenumbraSceneReaderInternals.h"

#include "vtkObjectFactory.h"

#include <fstream>
#include <set>
#include <sstream>

using namespace penumbra_scene_io;

void vtkPenumbraSceneReader::Internals::Build(
  const Ctx& ctx, const json& root, const char* dataDir, bool settingsOnly)
{
  ctx.Keys(root, "",
    { "description", "image", "background", "up", "camera", "objects", "lights", "technique",
      "distributed" });
  if (root.contains("description") && !root.at("description").is_string())
  {
    ctx.Fail("description", "expected a string");
  }
  this->Renderer = nullptr;
  this->ObjectNames.clear();
  this->Actors.clear();
  if (settingsOnly)
  {
    this->ReadSettings(ctx, root);
    return;
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
    ctx.Keys(img, "image", { "width", "height", "antialiasing" });
    this->Width = ctx.Integer(img, "image", "width", 640, 1, 16384);
    this->Height = ctx.Integer(img, "image", "height", 480, 1, 16384);
    // FXAA composes with the shadow pass on the EGL and OSMesa windows and smooths shadow
    // edges too (multisampling smooths only the geometry's silhouettes).
    const std::string antialiasing = ctx.String(img, "image", "antialiasing", "none");
    if (antialiasing != "none" && antialiasing != "fxaa")
    {
      ctx.Fail(Ctx::Sub("image", "antialiasing"),
        "expected \"none\" or \"fxaa\", got " + Quote(antialiasing));
    }
    this->Renderer->SetUseFXAA(antialiasing == "fxaa");
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
  this->ReadSettings(ctx, root);
}

// The shadow settings: the "technique" and "distributed" blocks.
void vtkPenumbraSceneReader::Internals::ReadSettings(const Ctx& ctx, const json& root)
{
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
  this->ReadDistributed(ctx, root);
}

// "distributed": how the ranks of a distributed render (ParaView on MPI ranks) share their
// casters; a single process has nothing to share and ignores it.
void vtkPenumbraSceneReader::Internals::ReadDistributed(const Ctx& ctx, const json& root)
{
  this->CasterExchange = "need";
  this->CasterMemoryBudget = 0.0;
  if (!root.contains("distributed"))
  {
    return;
  }
  const json& d = root.at("distributed");
  if (!d.is_object())
  {
    ctx.Fail("distributed", "expected an object with \"caster_exchange\" and \"memory_budget\"");
  }
  ctx.Keys(d, "distributed", { "caster_exchange", "memory_budget" });
  this->CasterExchange = ctx.String(d, "distributed", "caster_exchange", "need");
  if (this->CasterExchange != "need" && this->CasterExchange != "distributed" &&
    this->CasterExchange != "all")
  {
    ctx.Fail(Ctx::Sub("distributed", "caster_exchange"),
      "expected \"need\", \"distributed\" or \"all\", got " + Quote(this->CasterExchange));
  }
  this->CasterMemoryBudget = ctx.Number(d, "distributed", "memory_budget", 0.0);
  if (this->CasterMemoryBudget < 0.0)
  {
    ctx.Fail(Ctx::Sub("distributed", "memory_budget"),
      "must be 0 (no budget) or a positive number of MiB per rank, got " +
        d.at("memory_budget").dump());
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
    impl.Build(ctx, root, this->DataDirectory, this->SettingsOnly);
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

const char* vtkPenumbraSceneReader::GetCasterExchange()
{
  return this->Impl->CasterExchange.c_str();
}

double vtkPenumbraSceneReader::GetCasterMemoryBudget()
{
  return this->Impl->CasterMemoryBudget;
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
  os << indent << "SettingsOnly: " << (this->SettingsOnly ? "on" : "off") << "\n";
  os << indent << "Technique: " << this->Impl->TechniqueName << "\n";
  os << indent << "CasterExchange: " << this->Impl->CasterExchange << "\n";
  os << indent << "CasterMemoryBudget: " << this->Impl->CasterMemoryBudget << " MiB\n";
}
