#include "vtkPenumbraMapperDraws.h"

#include "vtkActor.h"
#include "vtkAssembly.h"
#include "vtkDataSetMapper.h"
#include "vtkGlyph3DMapper.h"
#include "vtkOpenGLHelper.h"
#include "vtkOpenGLPolyDataMapper.h"
#include "vtkPointGaussianMapper.h"
#include "vtkProperty.h"
#include "vtkSkybox.h"

#include <cctype>

namespace
{
// VTK 9.1 keeps the primitive a vtkOpenGLPolyDataMapper is building or drawing in a protected
// member; a pointer to it named through a derived class is the standard way to read it.
struct MapperPeek : public vtkOpenGLPolyDataMapper
{
  static const vtkOpenGLHelper* LastBound(vtkOpenGLPolyDataMapper* mapper)
  {
    return mapper->*(&MapperPeek::LastBoundBO);
  }
};
}

namespace penumbra_draws
{
bool DrawsSurface(vtkAbstractMapper* mapper, vtkProp* prop)
{
  auto* polyMapper = vtkOpenGLPolyDataMapper::SafeDownCast(mapper);
  auto* actor = vtkActor::SafeDownCast(prop);
  const vtkOpenGLHelper* bound = polyMapper ? MapperPeek::LastBound(polyMapper) : nullptr;
  if (!bound || !actor)
  {
    return false;
  }
  // Imposters draw points as triangles: splats (vtkPointGaussianMapper's helper), spheres
  // and sticks (molecules). Their triangles are no surface.
  for (const char* imposter : { "vtkOpenGLPointGaussianMapperHelper", "vtkOpenGLSphereMapper",
         "vtkOpenGLStickMapper" })
  {
    if (mapper->IsA(imposter))
    {
      return false;
    }
  }
  // vtkOpenGLPolyDataMapper::GetOpenGLMode(representation, primitive) == GL_TRIANGLES.
  const int type = bound->PrimitiveType;
  return actor->GetProperty()->GetRepresentation() == VTK_SURFACE &&
    (type == vtkOpenGLPolyDataMapper::PrimitiveTris ||
      type == vtkOpenGLPolyDataMapper::PrimitiveTriStrips);
}

bool DrawsThroughHooks(vtkProp* prop)
{
  if (vtkAssembly::SafeDownCast(prop))
  {
    return true;
  }
  auto* actor = vtkActor::SafeDownCast(prop);
  if (!actor || vtkSkybox::SafeDownCast(prop))
  {
    return false;
  }
  vtkMapper* mapper = actor->GetMapper();
  return vtkOpenGLPolyDataMapper::SafeDownCast(mapper) || vtkGlyph3DMapper::SafeDownCast(mapper) ||
    vtkPointGaussianMapper::SafeDownCast(mapper) || vtkDataSetMapper::SafeDownCast(mapper);
}

bool LightsWith(const std::string& fragmentShader, size_t index)
{
  const std::string name = "lightColor" + std::to_string(index);
  int uses = 0;
  for (size_t at = fragmentShader.find(name); at != std::string::npos;
       at = fragmentShader.find(name, at + name.size()))
  {
    const size_t end = at + name.size();
    const bool whole = (at == 0 ||
                         !(std::isalnum(static_cast<unsigned char>(fragmentShader[at - 1])) ||
                           fragmentShader[at - 1] == '_')) &&
      (end == fragmentShader.size() || !std::isdigit(static_cast<unsigned char>(fragmentShader[end])));
    uses += whole ? 1 : 0;
  }
  // One is the declaration; any other is the lighting code reading it.
  return uses >= 2 && fragmentShader.find("uniform vec3 " + name + ";") != std::string::npos;
}

bool HasViewPosition(const std::string& fragmentShader)
{
  return fragmentShader.find("vec4 vertexVC") != std::string::npos;
}
}
