#include "vtkPenumbraLightViews.h"

#include "vtkPenumbraVisibilityRules.h"

#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkLight.h"
#include "vtkMath.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkRenderer.h"
#include "vtkSMPTools.h"
#include "vtkShaderProgram.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <limits>
#include <mutex>
#include <regex>
#include <set>

namespace penumbra_light_views
{
namespace
{
bool Finite3(const double v[3])
{
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}
}

//------------------------------------------------------------------------------
bool View::Project(const double p[3], double& s, double& t, double& depth) const
{
  if (this->Perspective)
  {
    const double w = this->Dot(3, p);
    if (!(w > 0.0))
    {
      return false;
    }
    s = this->Dot(0, p) / w;
    t = this->Dot(1, p) / w;
    depth = w / this->Far;
    return true;
  }
  s = this->Dot(0, p);
  t = this->Dot(1, p);
  depth = this->Dot(2, p);
  return true;
}

//------------------------------------------------------------------------------
void View::ToFloatMatrix(float matrix[16]) const
{
  for (int r = 0; r < 4; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      matrix[4 * c + r] = static_cast<float>(this->Row[r][c]); // column-major for GLSL
    }
  }
}

//------------------------------------------------------------------------------
void Basis(const double f[3], double r[3], double u[3])
{
  const double helper[3] = { std::fabs(f[0]) < 0.9 ? 1.0 : 0.0, std::fabs(f[0]) < 0.9 ? 0.0 : 1.0,
    0.0 };
  vtkMath::Cross(f, helper, r);
  vtkMath::Normalize(r);
  vtkMath::Cross(r, f, u);
  vtkMath::Normalize(u);
}

//------------------------------------------------------------------------------
View PerspectiveView(const double apex[3], const double f[3], double tanHalf, const double box[6])
{
  View v;
  v.Perspective = true;
  v.TanHalf = tanHalf;
  double r[3], u[3];
  Basis(f, r, u);
  const double* axes[3] = { r, u, f };
  for (int a = 0; a < 2; ++a)
  {
    for (int c = 0; c < 3; ++c)
    {
      v.Row[a][c] = axes[a][c] / tanHalf;
    }
    v.Row[a][3] = -vtkMath::Dot(apex, axes[a]) / tanHalf;
  }
  for (int c = 0; c < 3; ++c)
  {
    v.Row[3][c] = f[c];
  }
  v.Row[3][3] = -vtkMath::Dot(apex, f);
  double far = 0.0;
  for (int i = 0; i < 8; ++i)
  {
    const double corner[3] = { box[i & 1], box[2 + ((i >> 1) & 1)], box[4 + ((i >> 2) & 1)] };
    far = std::max(far, std::sqrt(vtkMath::Distance2BetweenPoints(corner, apex)));
  }
  v.Far = far > 0.0 ? 1.01 * far : 1.0;
  // The apex region is where float projection loses too much (see the conservative
  // geometry stage).
  v.NearW = 2e-3 * v.Far;
  return v;
}

//------------------------------------------------------------------------------
View OrthographicView(const double f[3], const double box[6])
{
  View v;
  double r[3], u[3];
  Basis(f, r, u);
  const double* axes[3] = { r, u, f };
  double diagonal = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    diagonal += (box[2 * a + 1] - box[2 * a]) * (box[2 * a + 1] - box[2 * a]);
  }
  diagonal = std::sqrt(diagonal);
  for (int a = 0; a < 3; ++a)
  {
    double lo = std::numeric_limits<double>::max();
    double hi = -lo;
    for (int i = 0; i < 8; ++i)
    {
      const double corner[3] = { box[i & 1], box[2 + ((i >> 1) & 1)], box[4 + ((i >> 2) & 1)] };
      const double d = vtkMath::Dot(corner, axes[a]);
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
    // Samples on the box faces stay strictly inside the map and the depth range.
    const double pad = 1e-3 * std::max(hi - lo, diagonal) + 1e-12;
    lo -= pad;
    hi += pad;
    const double scale = a < 2 ? 2.0 / (hi - lo) : 1.0 / (hi - lo);
    const double shift = a < 2 ? -1.0 : 0.0;
    for (int c = 0; c < 3; ++c)
    {
      v.Row[a][c] = axes[a][c] * scale;
    }
    v.Row[a][3] = -lo * scale + shift;
  }
  v.Row[3][3] = 1.0;
  return v;
}

//------------------------------------------------------------------------------
bool LightSetup::Read(vtkLight* light, const double geometryOrigin[3], std::string& error)
{
  double lp[3], lf[3];
  light->GetTransformedPosition(lp);
  light->GetTransformedFocalPoint(lf);
  if (!Finite3(lp) || !Finite3(lf))
  {
    error = "light position or focal point is not finite";
    return false;
  }
  this->Off = !penumbra_rules::LightEmits(light);
  if (!light->GetPositional())
  {
    this->Type = Kind::Directional;
    for (int c = 0; c < 3; ++c)
    {
      this->Direction[c] = lp[c] - lf[c];
    }
    if (!(vtkMath::Normalize(this->Direction) > 0.0))
    {
      error = "directional light has no direction (position equals focal point)";
      return false;
    }
    return true;
  }
  std::copy(lp, lp + 3, this->Position);
  this->Cone = light->GetConeAngle();
  this->Type = this->Cone < 90.0 ? Kind::Spot : Kind::Point;
  if (this->Type == Kind::Spot)
  {
    for (int c = 0; c < 3; ++c)
    {
      this->Axis[c] = lf[c] - lp[c];
    }
    if (!(vtkMath::Normalize(this->Axis) > 0.0))
    {
      error = "spot light has no axis (position equals focal point)";
      return false;
    }
    this->CosCone = std::cos(vtkMath::RadiansFromDegrees(this->Cone));
  }
  for (int c = 0; c < 3; ++c)
  {
    this->Position[c] -= geometryOrigin[c];
  }
  return true;
}

//------------------------------------------------------------------------------
bool FrameInputs::Read(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
  vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility, std::string& error,
  bool allowArea)
{
  if (!renderer || !geometry || !samples || !light || !visibility)
  {
    error = "a renderer, geometry, samples, a light and an output array are all required";
    return false;
  }
  if (!allowArea && vtkPenumbraAreaLight::SafeDownCast(light))
  {
    error = "only point, spot and directional lights are handled, not area or linear lights";
    return false;
  }
  this->Window = vtkOpenGLRenderWindow::SafeDownCast(renderer->GetRenderWindow());
  if (!this->Window)
  {
    error = "an OpenGL render window is required";
    return false;
  }
  const std::string sampleProblem = samples->CheckArrays();
  if (!sampleProblem.empty())
  {
    error = sampleProblem;
    return false;
  }
  const vtkIdType n = samples->GetNumberOfSamples();
  vtkFloatArray* posArray = samples->GetPositions();
  vtkFloatArray* nrmArray = samples->GetNormals();
  vtkIntArray* propArray = samples->GetPropIndices();
  vtkIdTypeArray* triArray = samples->GetTriangleIds();
  const vtkIdType nTriangles = geometry->GetNumberOfTriangles();
  double samplesOrigin[3];
  geometry->GetOrigin(this->GeometryOrigin);
  samples->GetOrigin(samplesOrigin);
  if (!Finite3(this->GeometryOrigin))
  {
    error = "scene geometry has a non-finite origin";
    return false;
  }
  for (int c = 0; c < 3; ++c)
  {
    this->Shift[c] = samplesOrigin[c] - this->GeometryOrigin[c];
  }
  if (!this->Light.Read(light, this->GeometryOrigin, error))
  {
    return false;
  }
  this->NumberOfSamples = n;
  this->Positions = n ? posArray->GetPointer(0) : nullptr;
  this->Normals = n ? nrmArray->GetPointer(0) : nullptr;
  this->Props = n ? propArray->GetPointer(0) : nullptr;
  this->Triangles = n ? triArray->GetPointer(0) : nullptr;
  this->NumberOfTriangles = nTriangles;
  this->SceneTriangles = &geometry->GetTriangles();
  return true;
}

//------------------------------------------------------------------------------
FacingCounts ClassifyFacing(const LightSetup& light, vtkIdType n, const float* pos,
  const float* nrm, const int* props, const double shift[3], bool anyCaster, float* vis,
  unsigned char* pending, unsigned char pendingValue, unsigned char decidedValue,
  std::vector<vtkIdType>* pendingList)
{
  std::atomic<vtkIdType> lit(0), shadowed(0), waiting(0);
  const bool directional = light.Type == LightSetup::Kind::Directional;
  // Each chunk's pending samples, by the chunk's first sample (chunks run in any order).
  std::vector<std::pair<vtkIdType, std::vector<vtkIdType>>> chunks;
  std::mutex chunksMutex;
  vtkSMPTools::For(0, n,
    [&](vtkIdType begin, vtkIdType end)
    {
      vtkIdType localLit = 0, localShadowed = 0, localPending = 0;
      std::vector<vtkIdType> localList;
      for (vtkIdType s = begin; s < end; ++s)
      {
        pending[s] = decidedValue;
        if (props[s] < 0)
        {
          vis[s] = -1.0f; // background: its position and normal need not be read
          continue;
        }
        double p[3], normal[3];
        for (int c = 0; c < 3; ++c)
        {
          p[c] = static_cast<double>(pos[3 * s + c]) + shift[c];
          normal[c] = nrm[3 * s + c];
        }
        if (!Finite3(p) || !Finite3(normal))
        {
          vis[s] = -1.0f;
          continue;
        }
        if (light.Off)
        {
          vis[s] = 1.0f;
          ++localLit;
          continue;
        }
        double toLight[3];
        for (int c = 0; c < 3; ++c)
        {
          toLight[c] = directional ? light.Direction[c] : light.Position[c] - p[c];
        }
        bool facing = vtkMath::Dot(normal, toLight) > 0.0;
        if (facing && light.Type == LightSetup::Kind::Spot)
        {
          double fromLight[3] = { -toLight[0], -toLight[1], -toLight[2] };
          facing = vtkMath::Normalize(fromLight) > 0.0 &&
            vtkMath::Dot(fromLight, light.Axis) >= light.CosCone;
        }
        if (!facing)
        {
          vis[s] = 0.0f; // facing away (or outside the cone) is shadowed, as in the reference
          ++localShadowed;
          continue;
        }
        vis[s] = 1.0f;
        if (!anyCaster)
        {
          ++localLit;
          continue;
        }
        pending[s] = pendingValue;
        ++localPending;
        if (pendingList)
        {
          localList.push_back(s);
        }
      }
      lit += localLit;
      shadowed += localShadowed;
      waiting += localPending;
      if (!localList.empty())
      {
        const std::lock_guard<std::mutex> lock(chunksMutex);
        chunks.emplace_back(begin, std::move(localList));
      }
    });
  if (pendingList)
  {
    std::sort(
      chunks.begin(), chunks.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    pendingList->clear();
    pendingList->reserve(static_cast<size_t>(waiting.load()));
    for (const auto& chunk : chunks)
    {
      pendingList->insert(pendingList->end(), chunk.second.begin(), chunk.second.end());
    }
  }
  FacingCounts counts;
  counts.Lit = lit.load();
  counts.Shadowed = shadowed.load();
  counts.Pending = waiting.load();
  return counts;
}

//------------------------------------------------------------------------------
bool KeptBox::Serves(const double kept[6], const double box[6], double margin)
{
  double keptSide = 0.0, boxSide = 0.0;
  for (int c = 0; c < 3; ++c)
  {
    if (!(kept[2 * c] <= box[2 * c] && box[2 * c + 1] <= kept[2 * c + 1]))
    {
      return false;
    }
    keptSide = std::max(keptSide, kept[2 * c + 1] - kept[2 * c]);
    boxSide = std::max(boxSide, box[2 * c + 1] - box[2 * c]);
  }
  return keptSide <= (1.0 + 4.0 * margin) * boxSide;
}

//------------------------------------------------------------------------------
void KeptBox::Grow(const double box[6], double margin, double grown[6])
{
  const double m = margin * std::max({ box[1] - box[0], box[3] - box[2], box[5] - box[4] });
  for (int c = 0; c < 3; ++c)
  {
    grown[2 * c] = box[2 * c] - m;
    grown[2 * c + 1] = box[2 * c + 1] + m;
  }
}

//------------------------------------------------------------------------------
const double* KeptBox::Hold(const double box[6])
{
  if (!this->Valid || !Serves(this->Box, box, this->Margin))
  {
    Grow(box, this->Margin, this->Box);
    this->Valid = true;
  }
  return this->Box;
}

//------------------------------------------------------------------------------
void FitViews(const LightSetup& light, vtkIdType n, const float* pos, const double shift[3],
  const unsigned char* state, unsigned char pendingValue, std::vector<View>& views,
  std::vector<signed char>& sampleView, const std::vector<vtkIdType>* pending, KeptBox* kept)
{
  views.clear();
  sampleView.assign(static_cast<size_t>(n), -1);
  double box[6] = { std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
    std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
    std::numeric_limits<double>::max(), -std::numeric_limits<double>::max() };
  // Calls f(s) for every pending sample, from the list when there is one.
  auto forPending = [&](auto&& f)
  {
    if (pending)
    {
      for (vtkIdType s : *pending)
      {
        f(s);
      }
      return;
    }
    for (vtkIdType s = 0; s < n; ++s)
    {
      if (state[s] == pendingValue)
      {
        f(s);
      }
    }
  };
  bool any = false;
  forPending(
    [&](vtkIdType s)
    {
      any = true;
      for (int c = 0; c < 3; ++c)
      {
        const double v = static_cast<double>(pos[3 * s + c]) + shift[c];
        box[2 * c] = std::min(box[2 * c], v);
        box[2 * c + 1] = std::max(box[2 * c + 1], v);
      }
    });
  if (!any)
  {
    return;
  }
  if (kept)
  {
    const double* fit = kept->Hold(box);
    std::copy(fit, fit + 6, box);
  }
  using Kind = LightSetup::Kind;
  if (light.Type == Kind::Directional)
  {
    const double travel[3] = { -light.Direction[0], -light.Direction[1], -light.Direction[2] };
    views.push_back(OrthographicView(travel, box));
  }
  else if (light.Type == Kind::Spot && light.Cone <= 60.0)
  {
    views.push_back(PerspectiveView(
      light.Position, light.Axis, std::tan(vtkMath::RadiansFromDegrees(light.Cone + 1.0)), box));
  }
  else
  {
    for (int face = 0; face < 6; ++face)
    {
      double f[3] = { 0, 0, 0 };
      f[face / 2] = (face % 2) ? -1.0 : 1.0;
      views.push_back(PerspectiveView(light.Position, f, 1.0, box));
    }
  }
  forPending(
    [&](vtkIdType s)
    {
      if (views.size() == 1)
      {
        sampleView[static_cast<size_t>(s)] = 0;
        return;
      }
      double v[3];
      int best = 0;
      for (int c = 0; c < 3; ++c)
      {
        v[c] = static_cast<double>(pos[3 * s + c]) + shift[c] - light.Position[c];
        best = std::fabs(v[c]) > std::fabs(v[best]) ? c : best;
      }
      sampleView[static_cast<size_t>(s)] = static_cast<signed char>(2 * best + (v[best] < 0.0));
    });
}

//------------------------------------------------------------------------------
ShadowRay MakeShadowRay(
  const LightSetup& light, const double p[3], double diagonal, double epsilon, double tieFactor)
{
  ShadowRay ray;
  std::copy(p, p + 3, ray.P);
  ray.TMax = std::numeric_limits<double>::infinity();
  ray.Ok = true;
  if (light.Type == LightSetup::Kind::Directional)
  {
    std::copy(light.Direction, light.Direction + 3, ray.D);
  }
  else
  {
    for (int c = 0; c < 3; ++c)
    {
      ray.D[c] = light.Position[c] - p[c];
    }
    const double distance = vtkMath::Normalize(ray.D);
    ray.Ok = distance > 0.0;
    ray.TMax = distance * (1.0 - epsilon);
  }
  const penumbra_rules::RayBand band = penumbra_rules::SampleBand(p, diagonal, epsilon, tieFactor);
  ray.TieLimit = band.TieLimit;
  ray.ErrPos = 4e-6 * band.Scale;
  return ray;
}

//------------------------------------------------------------------------------
penumbra_rules::Hit TestShadowRay(
  const ShadowRay& ray, const penumbra_rules::ExactTriangle& triangle)
{
  int edge = 0;
  const penumbra_rules::Hit hit =
    penumbra_rules::SegmentTest(ray.P, ray.D, ray.TieLimit, ray.TMax, triangle, ray.ErrPos, edge);
  return hit == penumbra_rules::Hit::OnEdge ? penumbra_rules::Hit::Unknown : hit;
}

//------------------------------------------------------------------------------
penumbra_rules::Hit TestShadowRay(const ShadowRay& ray, const double* tri, vtkIdType id)
{
  penumbra_rules::ExactTriangle triangle;
  if (!penumbra_rules::MakeExactTriangle(tri, id, triangle))
  {
    return penumbra_rules::Hit::Unknown;
  }
  return TestShadowRay(ray, triangle);
}

//------------------------------------------------------------------------------
namespace
{
void SetDouble3(vtkShaderProgram* program, const std::string& name, const double v[3])
{
  const GLint location =
    glGetUniformLocation(static_cast<GLuint>(program->GetHandle()), name.c_str());
  if (location >= 0)
  {
    glUniform3d(location, v[0], v[1], v[2]);
  }
}
}

void SetClassifyUniforms(
  vtkShaderProgram* program, const LightSetup& setup, const std::string& suffix)
{
  SetDouble3(program, "classifyDirection" + suffix, setup.Direction);
  SetDouble3(program, "classifyPosition" + suffix, setup.Position);
  SetDouble3(program, "classifyAxis" + suffix, setup.Axis);
  SetDouble3(program, "classifyHalfU" + suffix, setup.HalfU);
  SetDouble3(program, "classifyHalfV" + suffix, setup.HalfV);
  const GLint cone = glGetUniformLocation(
    static_cast<GLuint>(program->GetHandle()), ("classifyCosCone" + suffix).c_str());
  if (cone >= 0)
  {
    glUniform1d(cone, setup.CosCone);
  }
}

//------------------------------------------------------------------------------
void SetLightUniforms(vtkShaderProgram* program, const LightSetup& setup, const std::string& suffix)
{
  const float position[3] = { static_cast<float>(setup.Position[0]),
    static_cast<float>(setup.Position[1]), static_cast<float>(setup.Position[2]) };
  const float toLight[3] = { static_cast<float>(setup.Direction[0]),
    static_cast<float>(setup.Direction[1]), static_cast<float>(setup.Direction[2]) };
  program->SetUniform3f(("lightPosition" + suffix).c_str(), position);
  program->SetUniform3f(("toLightDirection" + suffix).c_str(), toLight);
}

//------------------------------------------------------------------------------
std::string SuffixGlobals(const std::string& source, const std::string& suffix)
{
  // Declared names: the uniforms, constants and functions the snippets declare at column 0
  // (their bodies are indented, so locals and parameters keep their names).
  static const std::regex declared(
    R"((?:^|\n)(?:uniform\s+\w+|const\s+\w+|\w+)\s+(\w+)\s*(?:;|=|\())");
  static const std::set<std::string> keep = { "main", "penumbraSurface" };
  std::set<std::string> names;
  for (auto it = std::sregex_iterator(source.begin(), source.end(), declared);
       it != std::sregex_iterator(); ++it)
  {
    const std::string name = (*it)[1].str();
    if (!keep.count(name))
    {
      names.insert(name);
    }
  }
  // One pass over the identifiers, renaming the declared ones wherever they appear.
  std::string out;
  out.reserve(source.size() + 64);
  size_t i = 0;
  while (i < source.size())
  {
    const char c = source[i];
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_')
    {
      size_t j = i;
      while (j < source.size() &&
        (std::isalnum(static_cast<unsigned char>(source[j])) || source[j] == '_'))
      {
        ++j;
      }
      const std::string word = source.substr(i, j - i);
      out += word;
      if (names.count(word) && (i == 0 || source[i - 1] != '.'))
      {
        out += suffix;
      }
      i = j;
    }
    else if (std::isdigit(static_cast<unsigned char>(c)))
    {
      // Numbers (1e-6, 0.0LF) are copied whole so that their letters are not identifiers.
      size_t j = i;
      while (j < source.size() &&
        (std::isalnum(static_cast<unsigned char>(source[j])) || source[j] == '.' ||
          ((source[j] == '-' || source[j] == '+') &&
            (source[j - 1] == 'e' || source[j - 1] == 'E'))))
      {
        ++j;
      }
      out.append(source, i, j - i);
      i = j;
    }
    else
    {
      out += c;
      ++i;
    }
  }
  return out;
}

}
