/**
 * @file   vtkPenumbraLinkedListCompute.h
 * @brief  Private to Penumbra::ExactShadows: the GPU list construction of
 *         vtkPenumbraLinkedListShadows (Ferko 2014's head-pointer image, node pool and atomic
 *         counter, glsl/vtkPenumbraLinkedListBuildCS.glsl).
 *
 * The host projects the samples (the texel rule must be the CPU rasterizer's, in double
 * precision) and uploads (sample, texel) pairs; the shader links them into per-texel lists.
 * Link() reads the node pool back, Heads() the head pointers of the texels that hold lists and
 * then empties them on the GPU (no full clear per pass). A pool smaller than the pairs
 * overflows: the counter read back says so, and the caller lists the unlinked samples in a
 * further pass.
 *
 * Needs OpenGL 4.3 (compute shaders, shader storage buffers, buffer atomics); the shared
 * compute device (vtkPenumbraCompute.h) checks it and says what is missing.
 */

#ifndef vtkPenumbraLinkedListCompute_h
#define vtkPenumbraLinkedListCompute_h

#include "vtkPenumbraCompute.h"

#include <cstdint>
#include <string>
#include <vector>

class vtkOpenGLRenderWindow;
class vtkWindow;

namespace penumbra_llsm
{
/// An empty head pointer or the end of a list.
constexpr std::uint32_t NoNode = 0xFFFFFFFFu;

class ListCompute
{
public:
  /// Checks the context and compiles the program on first use; false with the reason in `why`.
  bool Prepare(vtkOpenGLRenderWindow* window, std::string& why);

  /**
   * Links the `count` (sample, texel) pairs of `items` into a head image of `texels` entries
   * with a pool of `capacity` nodes. `nodes` receives (sample, next) per node taken, at most
   * `capacity`; `requested` the counter, the nodes asked for (above `capacity`: overflow).
   */
  bool Link(const std::uint32_t* items, std::size_t count, std::size_t texels, std::size_t capacity,
    std::vector<std::uint32_t>& nodes, std::uint32_t& requested, std::string& why);

  /// The head pointers of `texels` after the last Link(); then empties the heads it linked.
  bool Heads(
    const std::vector<std::uint32_t>& texels, std::vector<std::uint32_t>& heads, std::string& why);

  /// Frees the program and buffers.
  void Release(vtkWindow* window);

private:
  bool Dispatch(std::size_t count, bool reset, std::string& why);

  penumbra_compute::Device Device;
  std::uint64_t Generation = 0;
  unsigned int Program = 0;
  int Offset = -1, Count = -1, Capacity = -1, Reset = -1;
  std::size_t HeadTexels = 0; // entries of the head image, all empty between calls
  std::size_t Items = 0;      // pairs of the last Link()
  bool Linked = false;        // heads hold the last Link()'s lists
};
}

#endif
