/**
 * @class   vtkPenumbraSceneReader
 * @brief   Builds a renderer (props, lights, camera) from a Penumbra JSON scene file.
 *
 * The scene file is the middleware's description of what to render: meshes by file or from a
 * built-in generator, with transform, colour, material and shadow flags; lights (directional,
 * spot, point, rectangular area, linear); camera; image size; and the shadow technique with
 * its options. The schema is documented in Data/Scenes/SCHEMA.md.
 *
 * Validation is strict and happens before anything is rendered: the first problem found is
 * reported as one message that names the file, the field and what is wrong, e.g.
 * `city.json: lights[1].type: unknown light type "sun" (expected directional, spot, point,
 * goniometric, area or linear)`. Read() then returns 0 and GetErrorMessage() holds that message.
 *
 * Relative file paths are resolved against the scene file's folder. A path starting with
 * `$DATA/` is resolved against DataDirectory (default: the `PENUMBRA_DATA_DIR` environment
 * variable, else the data folder configured at build time).
 */

#ifndef vtkPenumbraSceneReader_h
#define vtkPenumbraSceneReader_h

#include "vtkObject.h"
#include "vtkPenumbraSceneIOModule.h" // For export macro

#include <memory> // For std::unique_ptr

class vtkActor;
class vtkRenderer;

class VTKPENUMBRASCENEIO_EXPORT vtkPenumbraSceneReader : public vtkObject
{
public:
  static vtkPenumbraSceneReader* New();
  vtkTypeMacro(vtkPenumbraSceneReader, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Most lights a scene file may have (switched on or off). VTK 9.1's lighting shader
   * declares about seven uniforms per positional light, and OpenGL 4.5 guarantees only 256
   * vec4 fragment uniform vectors (GL_MAX_FRAGMENT_UNIFORM_VECTORS): thousands of lights
   * take a minute to compile and then fail to link. Of these lights, the shadow pass shadows
   * as many as the receivers' texture units allow (GL_MAX_TEXTURE_IMAGE_UNITS - 8: 8 on a
   * minimal OpenGL 4.5, 24 on Mesa llvmpipe). A scene with more lights is refused before any
   * mesh is read.
   */
  enum
  {
    MaximumNumberOfLights = 32
  };

  ///@{
  /**
   * The JSON scene file to read. Default: none.
   */
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  ///@{
  /**
   * Folder that `$DATA/` paths point to. Default: `PENUMBRA_DATA_DIR` from the environment,
   * else the build-time data folder.
   */
  vtkSetStringMacro(DataDirectory);
  vtkGetStringMacro(DataDirectory);
  ///@}

  /**
   * Reads FileName and builds the scene. Returns 1 on success, 0 on any error (see
   * GetErrorMessage(); the error is also reported through vtkErrorMacro).
   */
  int Read();

  /**
   * Same as Read() for JSON text; `label` names it in messages and `baseDirectory` resolves
   * its relative paths.
   */
  int ReadFromString(const char* json, const char* label, const char* baseDirectory);

  ///@{
  /**
   * Read only the scene's shadow settings, the "technique" and "distributed" blocks, checked
   * as always (an unknown top-level key is still refused; objects, lights and camera are not
   * read and not required): for applying a scene's settings to another pipeline, e.g. a
   * ParaView view (penumbra_paraview.apply_scene_settings). GetRenderer() is then null.
   * Default off.
   */
  vtkSetMacro(SettingsOnly, bool);
  vtkGetMacro(SettingsOnly, bool);
  vtkBooleanMacro(SettingsOnly, bool);
  ///@}

  /**
   * The first problem found by the last Read(), empty after a success.
   */
  const char* GetErrorMessage();

  /**
   * The renderer holding the scene's props, lights and camera (nullptr before a successful
   * read). A new renderer is made by every successful read.
   */
  vtkRenderer* GetRenderer();

  ///@{
  /**
   * Image size in pixels from the scene's "image" block. Default 640 x 480.
   */
  int GetWidth();
  int GetHeight();
  ///@}

  /**
   * Technique named by the scene's "technique" block; "auto" (a technique chosen per light,
   * see vtkPenumbraAutoShadows) if none is given.
   */
  const char* GetTechniqueName();

  /**
   * The technique block's other members as JSON text ("{}" if none), for the technique to
   * validate. Errors in them are to be reported as `<file>: technique.<option>: ...`.
   */
  const char* GetTechniqueOptions();

  ///@{
  /**
   * The scene's "distributed" block: how the ranks of a distributed render (the ParaView
   * view on MPI ranks, vtkPVPenumbraShadowView's CasterExchange and CasterMemoryBudget; see
   * penumbra_paraview.apply_scene_settings) share their casters. CasterExchange "need"
   * (default), "distributed" or "all"; CasterMemoryBudget in MiB per rank, 0 (default) for
   * none: a need-based exchange that would hold more than that for the other ranks sends rays
   * instead. A single process has nothing to share and ignores both. See SettingsOnly.
   */
  const char* GetCasterExchange();
  double GetCasterMemoryBudget();
  ///@}

  /**
   * A label for messages about this scene: the file name, or the label given to
   * ReadFromString.
   */
  const char* GetSceneLabel();

  ///@{
  /**
   * The scene's objects, in file order.
   */
  int GetNumberOfObjects();
  const char* GetObjectName(int index);
  vtkActor* GetObjectActor(int index);
  ///@}

protected:
  vtkPenumbraSceneReader();
  ~vtkPenumbraSceneReader() override;

  char* FileName;
  char* DataDirectory;
  bool SettingsOnly = false;

private:
  vtkPenumbraSceneReader(const vtkPenumbraSceneReader&) = delete;
  void operator=(const vtkPenumbraSceneReader&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
