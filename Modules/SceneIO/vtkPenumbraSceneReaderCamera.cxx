// vtkPenumbraSceneReader: the scene's up axis and its camera.

#include "vtkPenumbraSceneReaderInternals.h"

#include "vtkCamera.h"

#include <algorithm>

namespace penumbra_scene_io
{
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
}

using namespace penumbra_scene_io;

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
