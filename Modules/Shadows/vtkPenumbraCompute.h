/**
 * @file   vtkPenumbraCompute.h
 * @brief  Part of the contract (Penumbra::Shadows): what every GL 4.3 compute path shares
 *         (the GEARS masks, vtkPenumbraGearsCompute.h; the LLSM lists,
 *         vtkPenumbraLinkedListCompute.h): the context and feature check, shader storage
 *         buffers by binding point, program compilation and release.
 *
 * Raw GL (VTK 9.1's vtkShader has no compute stage and vtkOpenGLBufferObject no SSBO type).
 * The features are checked once per context: OpenGL 4.3 (compute shaders, shader storage
 * buffers) and the number of storage blocks a compute shader of the caller needs; Prepare()
 * says which is missing, so a pass that cannot run reports it and falls back.
 */

#ifndef vtkPenumbraCompute_h
#define vtkPenumbraCompute_h

#include <cstdint>
#include <string>
#include <vector>

class vtkOpenGLRenderWindow;
class vtkWindow;

namespace penumbra_compute
{
/// "OpenGL error 0x...".
std::string GLErrorText(unsigned int error);

/// Scoped: `program` bound, VTK's shader cache told that its program is no longer bound,
/// storage bindings and the program released on exit.
class ProgramScope
{
public:
  ProgramScope(vtkOpenGLRenderWindow* window, unsigned int program);
  ~ProgramScope();
  ProgramScope(const ProgramScope&) = delete;
  ProgramScope& operator=(const ProgramScope&) = delete;
};

/// One compute user's GL objects in one context: storage buffers by binding point and the
/// programs it compiled.
class Device
{
public:
  Device() = default;
  ~Device() = default;
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  /**
   * Makes `window`'s context current and checks, once per context, that it runs compute
   * shaders with `blocks` storage blocks. `user` names the caller in the reasons ("GEARS").
   * A new window drops every object of the old one (Generation() changes). False, with the
   * reason in `why`, when the path cannot run.
   */
  bool Prepare(vtkOpenGLRenderWindow* window, int blocks, const char* user, std::string& why);

  /// Counts the contexts this device started afresh in: programs of another generation are gone.
  std::uint64_t Generation() const { return this->Generations; }

  /// Compiles and links a compute program from `source` (with its #version line).
  bool Compile(const std::string& source, unsigned int& program, std::string& why);

  /**
   * Makes buffer `binding` at least `bytes` long (never empty), fills its start with `data`
   * when given, and binds it to storage binding point `binding`.
   */
  bool Upload(int binding, const void* data, std::size_t bytes, std::string& why);

  /// Rebinds buffer `binding` to its binding point (another user may have used it).
  void Bind(int binding) const;

  /// Copies the first `bytes` of buffer `binding` into `data`.
  bool Download(int binding, void* data, std::size_t bytes, std::string& why) const;

  /// The GL name of buffer `binding` (0 before its first Upload).
  unsigned int Buffer(int binding) const;

  /// The window whose context holds the objects (null before Prepare).
  vtkOpenGLRenderWindow* GetWindow() const { return this->Window; }

  /// Bytes uploaded since the counter was last reset by the caller.
  std::size_t UploadedBytes = 0;

  /// Frees the programs and buffers (the window's context is made current first).
  void Release(vtkWindow* window);

private:
  // Drops every handle without deleting it (its context is gone or already cleaned).
  void Forget();

  vtkOpenGLRenderWindow* Window = nullptr;
  std::vector<unsigned int> Buffers;
  std::vector<std::size_t> Capacity;
  std::vector<unsigned int> Programs;
  std::int64_t MaxBlockBytes = 0;
  int MaxBlocks = 0;
  bool Checked = false;
  std::string Unsupported; // non-empty: the context has no compute shaders (checked once)
  std::uint64_t Generations = 0;
};
}

#endif
