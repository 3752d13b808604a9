/**
 * @class   vtkPenumbraViewSamplesPass
 * @brief   Renders the view samples (G-buffer) of the opaque props, or of the nearest
 *          translucent surface, for shadow techniques.
 *
 * For every pixel of the renderer's viewport the pass records what the camera sees: the
 * surface position relative to the scene geometry's rebasing origin (32-bit float, so city
 * coordinates around 1e6 m keep centimetre precision; the 16-bit positions VTK's SSAO pass
 * keeps are not enough), its facet normal turned toward the camera, the index of its prop in
 * the vtkPenumbraSceneGeometry, and the mapper's primitive id, which the geometry maps to its
 * own triangle index so techniques and the reference can exclude a sample's own triangle.
 *
 * The samples stay on the GPU as textures. GetSamples() reads them back into a
 * vtkPenumbraViewSamples for CPU techniques and for the exact reference, once per Render()
 * and only when asked: by default the G-buffer's float32 positions and normals, the very
 * values GPU techniques read, so CPU and GPU techniques and the reference decide every
 * sample on the same numbers; or (READ_BACK_IDS) only the prop index and primitive id, each
 * sample's position and normal then rebuilt in double precision from its triangle and the
 * pixel centre's camera ray (see SetReadBackMode()).
 * Props that do not receive shadows (vtkPenumbraShadowKeys) occlude but give no sample
 * (prop index -1).
 *
 * Props whose shader has no view-space position (lighting turned off) still occlude but give
 * invalid samples (they receive no light, so no shadow either).
 *
 * With Translucent on, the pass renders the translucent geometry instead (VTK's translucent
 * pass, with depth writes forced on and blending off) and keeps, per pixel, the nearest
 * translucent surface, so that techniques can shadow translucent props too.
 */

#ifndef vtkPenumbraViewSamplesPass_h
#define vtkPenumbraViewSamplesPass_h

#include "vtkOpenGLRenderPass.h"
#include "vtkPenumbraShadowsModule.h" // For export macro

#include <memory> // For std::unique_ptr
#include <string> // For AddSurfaceDeclarations

class vtkPenumbraSceneGeometry;
class vtkPenumbraViewSamples;
class vtkShaderProgram;
class vtkTextureObject;
class vtkWindow;

class VTKPENUMBRASHADOWS_EXPORT vtkPenumbraViewSamplesPass : public vtkOpenGLRenderPass
{
public:
  static vtkPenumbraViewSamplesPass* New();
  vtkTypeMacro(vtkPenumbraViewSamplesPass, vtkOpenGLRenderPass);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The extracted scene the samples refer to (origin, prop indices, triangle ids). It must
   * be up to date before Render(). Default: none (Render() then reports an error).
   */
  void SetGeometry(vtkPenumbraSceneGeometry* geometry);
  vtkPenumbraSceneGeometry* GetGeometry();
  ///@}

  ///@{
  /**
   * Sample the translucent geometry (nearest translucent surface per pixel) instead of the
   * opaque props. Default off.
   */
  vtkSetMacro(Translucent, bool);
  vtkGetMacro(Translucent, bool);
  vtkBooleanMacro(Translucent, bool);
  ///@}

  /**
   * What ReadSamples() reads back from the GPU.
   */
  enum ReadBackModes
  {
    /// All three targets (48 bytes per pixel): float32 positions and normals as rendered.
    READ_BACK_POSITIONS = 0,
    /// The primitive target only (16 bytes per pixel): prop index and primitive id. The
    /// position is the intersection of the pixel centre's camera ray (x + 0.5, y + 0.5) with
    /// the plane of the sample's triangle, computed in double from the geometry's rebased
    /// triangles and clamped to the triangle, then stored as float relative to the origin;
    /// the normal is the triangle's unit normal turned toward the camera. Samples that have
    /// no triangle to rebuild from (MapPrimitiveId() gives -1, e.g. composite inputs), whose
    /// triangle has no normal (zero area), or whose ray is parallel to the triangle's plane
    /// keep the G-buffer's float32 position and normal: those rows are read as in
    /// READ_BACK_POSITIONS (see GetNumberOfFallbackSamples()).
    READ_BACK_IDS = 1
  };

  ///@{
  /**
   * What ReadSamples() reads back (ReadBackModes). Default READ_BACK_POSITIONS: the samples
   * GPU techniques see. READ_BACK_IDS reads a third of the bytes and gives positions exact to
   * double precision before rounding to float, at about the same total cost on llvmpipe; but
   * a GPU technique then decides a sample on other numbers than the reference does (a point
   * light lying in a plane, torture/point_light_on_surface: the plane's float positions sit
   * on either side of the light, the rebuilt ones exactly in it), so it is not the default.
   */
  vtkSetClampMacro(ReadBackMode, int, READ_BACK_POSITIONS, READ_BACK_IDS);
  vtkGetMacro(ReadBackMode, int);
  void SetReadBackModeToPositions() { this->SetReadBackMode(READ_BACK_POSITIONS); }
  void SetReadBackModeToIds() { this->SetReadBackMode(READ_BACK_IDS); }
  ///@}

  /**
   * Number of valid samples of the last ReadSamples() in READ_BACK_IDS mode that kept the
   * G-buffer's float position and normal (see READ_BACK_IDS); 0 in READ_BACK_POSITIONS mode.
   */
  vtkIdType GetNumberOfFallbackSamples();

  /**
   * The samples of the last Render(), read back from the GPU at the first call after it
   * (the window's context is made current).
   */
  vtkPenumbraViewSamples* GetSamples();

  /**
   * Reads the last Render()'s samples into rows [firstRow, firstRow + height) of `target`,
   * which must be as wide as the viewport and tall enough; its origin and camera position
   * are set to this pass's. Returns false (with an error) otherwise.
   */
  bool ReadSamples(vtkPenumbraViewSamples* target, int firstRow);

  ///@{
  /**
   * GPU copies of the last Render(): RGBA32F position (xyz, w = 1 where valid), RGBA32F
   * normal (xyz) with the prop index in w, RGBA32F primitive id as two exact 16-bit halves
   * (x low, y high) with the prop index in z (-1: no sample) and w = 1 where valid, so that
   * this one target identifies the surface.
   */
  vtkTextureObject* GetPositionTexture();
  vtkTextureObject* GetNormalTexture();
  vtkTextureObject* GetPrimitiveTexture();
  vtkTextureObject* GetDepthTexture(); ///< float depth, 1 where no surface was seen
  ///@}

  ///@{
  /**
   * The GLSL function `penumbraSurface(vertexVC, out position, out normal)` that gives a
   * fragment the position and facet normal its view sample records, with its uniforms; and
   * those uniforms for the camera of the last Render(). Shaders that look shadows up while
   * shading (vtkPenumbraShadowPass) use them to see exactly the samples of this pass.
   */
  static const char* GetSurfaceDeclarations();
  void SetSurfaceUniforms(vtkShaderProgram* program);
  ///@}

  /**
   * Whether `prop`, drawn through the hooks, gets view samples: it is a prop of the scene
   * geometry (by pointer, or by the property keys a device actor shares) that receives
   * shadows. The one rule for who receives: props that do not are drawn unshadowed by every
   * technique, the receivers' shader lookups included.
   */
  bool GivesSamples(vtkProp* prop);

  /**
   * Indexes the geometry's props by pointer and by their current property keys, for
   * GivesSamples() and the samples' prop indices. Render() calls it after PreRender() has
   * given every drawn prop its keys; a pass that draws with these rules on a frame whose
   * samples are not rendered calls it after its own PreRender().
   */
  void IndexProps();

  /**
   * Replaces `tag` in a fragment shader by GetSurfaceDeclarations() followed by `more`, and
   * enables the extension they read the coverage mask with (where VTK declares its version).
   */
  static void AddSurfaceDeclarations(
    std::string& fragmentShader, const std::string& tag, const std::string& more);

  /**
   * The statements that declare `vec3 penumbraP, penumbraN` and fill them with
   * penumbraSurface(vertexVC, ...): placed where the mapper's control flow is still uniform
   * (VTK's //VTK::UniformFlow::Impl), as screen-space derivatives need.
   */
  static const char* GetSurfaceCall();

  /**
   * Takes the camera of `renderer` for SetSurfaceUniforms() without rendering (Render()
   * does it too): a frame whose samples are rendered only on demand still shades its
   * shader lookups with the current camera.
   */
  void UpdateView(vtkRenderer* renderer);

  void Render(const vtkRenderState* s) override;
  void ReleaseGraphicsResources(vtkWindow* w) override;

  bool PreReplaceShaderValues(std::string& vertexShader, std::string& geometryShader,
    std::string& fragmentShader, vtkAbstractMapper* mapper, vtkProp* prop) override;
  bool PostReplaceShaderValues(std::string& vertexShader, std::string& geometryShader,
    std::string& fragmentShader, vtkAbstractMapper* mapper, vtkProp* prop) override;
  bool SetShaderParameters(vtkShaderProgram* program, vtkAbstractMapper* mapper, vtkProp* prop,
    vtkOpenGLVertexArrayObject* VAO = nullptr) override;

protected:
  vtkPenumbraViewSamplesPass();
  ~vtkPenumbraViewSamplesPass() override;

  bool Translucent = false;
  int ReadBackMode = READ_BACK_POSITIONS;

private:
  vtkPenumbraViewSamplesPass(const vtkPenumbraViewSamplesPass&) = delete;
  void operator=(const vtkPenumbraViewSamplesPass&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
