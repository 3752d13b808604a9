/**
 * @class   vtkPVPenumbraShadowView
 * @brief   ParaView render view that draws with a Penumbra shadow technique.
 *
 * A vtkPVRenderView whose render pass is the shadow pass of one technique of Penumbra's
 * registry (vtkPenumbraTechniques), chosen by name with options as JSON text, exactly as in
 * scene files and `penumbra-render --technique`. ParaView composes its own passes around the
 * one given to vtkPVSynchronizedRenderer::SetRenderPass (FXAA, image processing, the camera
 * pass, and IceT's compositing pass under MPI), so the view hands over the technique's pass
 * without Penumbra's camera pass.
 *
 * The technique is installed lazily, at the next render: ParaView pushes ShadowTechnique and
 * ShadowOptions one at a time, and a new technique with the previous technique's options
 * would be refused. A refused technique or option is reported (vtkErrorMacro, with the
 * registry's message naming the option) and the view keeps drawing with its last valid one;
 * GetShadowRequestRefused() then says so, and vtkSMPenumbraShadowViewProxy puts the proxy's
 * properties back to what draws (GetInstalledTechnique(), GetInstalledShadowOptions(),
 * GetInstalledOptionValues()).
 *
 * Level of detail: vtkPVLODActor draws a decimated mesh during interaction when the data
 * exceeds the LOD threshold. This view never does (the threshold stays infinite, whatever
 * the settings say): shadows are computed for the geometry that is drawn, and a decimated
 * mesh would shadow itself wrongly. Interaction on large data is therefore slower than in
 * ParaView's plain render view.
 *
 * Distributed rendering (pvbatch or pvserver on several MPI ranks, IceT compositing): each
 * rank draws only its own piece of the data, but a shadow on it may be cast by another rank's
 * piece. Before every distributed render the view therefore exchanges casters between the
 * ranks (penumbra::CasterExchange, over the global controller, in world coordinates, double
 * precision, bit for bit as each rank extracted them) and hands the triangles received to
 * the shadow pass as shadow-only props (vtkPenumbraSceneGeometry::SetShadowOnlyProps): they
 * cast, they are not drawn. Receivers stay local and IceT composites as it does without
 * shadows. CasterExchange chooses what is sent: `need` (the default) sends a peer only the
 * triangles that can shadow its receivers for the view's lights, with the same exact answer;
 * `all` sends every caster to every rank. Nothing is sent again until some rank's casters
 * or receivers, or the lights, change (one integer all-reduce per frame otherwise), and a
 * triangle found on several ranks (data replicated or boundary cells duplicated) is kept
 * once (docs/paraview.md has the measurements).
 *
 * Loading the plugin registers Penumbra's headless (EGL) render window when no X display is
 * set (vtkPenumbraHeadlessFactory), so pvpython and pvbatch render without an X server.
 * pvbatch and pvserver then draw each view into a vtkGenericOpenGLRenderWindow that shares
 * that window's context (ParaView's vtkOffscreenOpenGLRenderWindow), which runs VTK's
 * vtkOpenGLRenderWindow::OpenGLInitContext() at every render until it succeeds. It never
 * does: Debian's GLEW is built for GLX, and glewInit() loads every GL entry point, then returns
 * GLEW_ERROR_NO_GLX_DISPLAY (glewGetErrorString: "Unknown error") because an EGL context has
 * no GLX display. Penumbra's own windows treat that code as success; the view observes its
 * window's errors and drops that one message when the GL part of GLEW did load (GL 3.2
 * present), passing every other error on to VTK's output window as before.
 */

#ifndef vtkPVPenumbraShadowView_h
#define vtkPVPenumbraShadowView_h

#include "vtkPVRenderView.h"
#include "vtkPenumbraParaViewViewModule.h" // For export macro

#include <memory> // For std::unique_ptr
#include <string> // For std::string

class vtkStringArray;

class VTKPENUMBRAPARAVIEWVIEW_EXPORT vtkPVPenumbraShadowView : public vtkPVRenderView
{
public:
  static vtkPVPenumbraShadowView* New();
  vtkTypeMacro(vtkPVPenumbraShadowView, vtkPVRenderView);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The technique's name in Penumbra's registry; empty (ParaView's initial value: its
   * string-list domain is filled from the server only after the view exists) or unset means
   * vtkPenumbraTechniques::GetDefaultTechnique(), `auto`. Takes effect at the next render.
   */
  void SetShadowTechnique(const char* name);
  const char* GetShadowTechnique() { return this->Technique.c_str(); }
  ///@}

  ///@{
  /**
   * The technique's options as a JSON object ("" or nullptr: the registry's defaults).
   * Takes effect at the next render.
   */
  void SetShadowOptions(const char* options);
  const char* GetShadowOptions() { return this->Options.c_str(); }
  ///@}

  ///@{
  /**
   * One option of one technique, `key` being "<technique>/<option>" (e.g.
   * "shadowmap/resolution"): the generated per-option properties of the proxy call these
   * (one per option type; booleans as 0/1). The technique's options are these values, with
   * the ones ShadowOptions names replaced by its; the registry validates them when the
   * technique is installed (at the next render). Unknown keys are refused with an error.
   */
  void SetShadowOptionInteger(const char* key, int value);
  void SetShadowOptionNumber(const char* key, double value);
  void SetShadowOptionBoolean(const char* key, int value);
  void SetShadowOptionChoice(const char* key, const char* value);
  ///@}

  /**
   * The registered technique names, the registry's default first (a StringListDomain offers
   * its first string as the property's default).
   */
  vtkStringArray* GetShadowTechniqueNames();

  /**
   * Every technique with its options, defaults and ranges (vtkPenumbraTechniques::
   * GetTechniqueList(), as `penumbra-render --list-techniques` prints it).
   */
  const char* GetShadowTechniqueHelp();

  /**
   * The name of the technique the view draws with now (empty before the first render).
   */
  const char* GetInstalledTechnique() { return this->InstalledTechnique.c_str(); }

  ///@{
  /**
   * What the installed technique was installed with: the ShadowOptions text, and its option
   * properties' values as a JSON object ({"resolution": 2048, ...}). Empty before the first
   * installation.
   */
  const char* GetInstalledShadowOptions() { return this->InstalledOptionsText.c_str(); }
  const char* GetInstalledOptionValues() { return this->InstalledOptionValues.c_str(); }
  ///@}

  /**
   * True when the last render tried a request (technique and options) that the registry
   * refused; the view still draws with GetInstalledTechnique(). False once a request is
   * installed, or when the request is what is installed.
   */
  bool GetShadowRequestRefused() { return this->Refused; }

  /**
   * What the last frame did, per light: the technique that shadowed it and why, and its
   * statistics (counts and phase times, whatever the technique;
   * vtkPenumbraShadowPass::GetExplanation()). Empty without a Penumbra pass.
   */
  const char* GetShadowReport();

  /**
   * Ignored: the view never renders a decimated LOD mesh (see the class description).
   */
  void SetLODRenderingThreshold(double) override;

  ///@{
  /**
   * What distributed rendering sends between the ranks: 0 `need` (default), the casters
   * that can shadow each peer's receivers; 1 `all`, every caster to every rank; 2
   * `distributed`, no casters: each rank keeps its own, and the shadow rays of its hard
   * lights that its casters leave lit go to the ranks whose casters they may cross
   * (vtkPenumbraRayQueries; area lights are then shadowed by the rank's own casters only).
   * Other values are refused with an error. Takes effect at the next render.
   */
  void SetCasterExchange(int mode);
  int GetCasterExchange() { return this->CasterExchange; }
  ///@}

  ///@{
  /**
   * Memory budget per rank for the other ranks' casters, in MiB (0, the default: none).
   * When the need-based exchange would make some rank hold more (about 297 bytes a
   * triangle), that exchange is made `distributed` instead, on every rank. A negative or
   * non-finite budget is refused with an error. A scene file's "distributed" block sets it
   * too (penumbra_paraview.apply_scene_settings).
   */
  void SetCasterMemoryBudget(double megabytes);
  double GetCasterMemoryBudget() { return this->CasterMemoryBudget; }
  ///@}

  ///@{
  /**
   * The last caster exchange on this rank (distributed rendering only): its wall time in ms,
   * the other ranks' caster triangles held (duplicates of triangles already held removed),
   * the bytes received and sent and the triangles sent (summed over the peers). Zero before
   * an exchange; unchanged by frames that did not need one. GetNumberOfCasterGathers()
   * counts the exchanges done.
   */
  double GetLastCasterGatherMs();
  vtkIdType GetNumberOfRemoteCasterTriangles();
  vtkIdType GetCasterBytesReceived();
  vtkIdType GetCasterBytesSent();
  vtkIdType GetNumberOfCasterTrianglesSent();
  int GetNumberOfCasterGathers();
  ///@}

  ///@{
  /**
   * Distributed ray queries (CasterExchange `distributed`) in the last frame on this rank:
   * rays sent to other ranks (summed over them) and bytes sent and received (queries and
   * answers). Zero in the other modes.
   */
  vtkIdType GetNumberOfRaysSent();
  vtkIdType GetRayBytesSent();
  vtkIdType GetRayBytesReceived();
  ///@}

  /**
   * Every rank's figures of the last caster exchange, a line each (on the first rank; see
   * penumbra::CasterExchange::GetReport()). Empty before the first exchange.
   */
  const char* GetCasterExchangeReport();

protected:
  vtkPVPenumbraShadowView();
  ~vtkPVPenumbraShadowView() override;

  void Render(bool interactive, bool skip_rendering) override;
  void AboutToRenderOnLocalProcess(bool interactive) override;

private:
  vtkPVPenumbraShadowView(const vtkPVPenumbraShadowView&) = delete;
  void operator=(const vtkPVPenumbraShadowView&) = delete;

  // Installs the requested technique if it changed since the last render.
  void UpdateShadowPass();

  // The option values the per-option properties set (GetOptions() of the key's technique),
  // and the JSON text the technique is installed with.
  bool SetOptionValue(const char* key, const std::string& json);
  std::string ComposeOptions(const std::string& technique);

  // Distributed rendering: gives the pass the other ranks' casters it needs (see the class
  // description). Collective: every rendering rank calls it for every render.
  void GatherCasters();

  // Whether the pass sends this rank's rays to the others (the distributed mode).
  bool RayQueriesActive();

  // ErrorEvent observer of the render window: drops the known-harmless GLEW message (see the
  // class description), passes every other error on.
  void OnWindowError(vtkObject* window, unsigned long event, void* text);
  unsigned long WindowErrorObserver = 0;

  std::string Technique;
  std::string Options;
  std::string InstalledTechnique;
  std::string InstalledOptions;      // the composed JSON it was installed with
  std::string InstalledOptionsText;  // GetInstalledShadowOptions()
  std::string InstalledOptionValues; // GetInstalledOptionValues()
  bool Refused = false;
  int CasterExchange = 0;
  double CasterMemoryBudget = 0.0;
  std::string Report; // GetShadowReport()'s text
  bool Tried = false;
  std::string TriedTechnique;
  std::string TriedOptions;
  std::string Help;
  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
