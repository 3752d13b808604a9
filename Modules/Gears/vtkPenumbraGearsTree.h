/**
 * @file   vtkPenumbraGearsTree.h
 * @brief  Private to Penumbra::Gears: a bounding volume hierarchy over GEARS's casters,
 *         for the view samples whose grid cell meets too many triangles (dense meshes under
 *         large lights).
 *
 * GEARS's per-cell lists (Wang, Wang, Shi, Popescu, "GEARS: A General and Efficient Algorithm
 * for Rendering Shadows", Computer Graphics Forum 33(6), 2014, A.3) are conservative for the
 * whole cell: on a scanned statue under a light larger than the statue a cell meets thousands
 * of triangles, each covering a fraction of one light sample, and a mask built from the list
 * costs O(k) per triangle even when the light samples it covers are blocked already (the
 * paper's Table 3: the cost grows with the light). The paper's future work names a secondary
 * subdivision of such "hot" cells; this tree is that subdivision, per view sample: a sample
 * walks it near nodes first, and skips a node when the node cannot reach one of its light
 * samples that is still open: outside the pyramid from the sample to the light, farther from
 * the light than the sample, or projecting from the sample onto light samples that earlier
 * triangles already block (occluder fusion in the mask). The work per sample then follows
 * the light samples still open rather than the cell's list length; but a light sample is
 * only blocked by a triangle that covers it, so where the triangles are smaller than the
 * light-sample spacing each open light sample still costs a descent to a leaf, much like a
 * ray.
 *
 * The tree is built once per caster set (median splits on the longest centroid axis, at most
 * LeafSize triangles per leaf); per frame and side of the light plane only its boxes are
 * refitted in the light's frame (Refit()), from the triangles' boxes there.
 */

#ifndef vtkPenumbraGearsTree_h
#define vtkPenumbraGearsTree_h

#include <cstdint>
#include <vector>

namespace penumbra_gears
{
struct TreeNode
{
  double Lo[3], Hi[3]; // box of the node's triangles, in the casters' (rebased) frame
  std::uint32_t First; // inner: index of the first child (the second follows); leaf: into Order
  std::uint32_t Count; // leaf: triangles; 0 for an inner node
};

struct Tree
{
  static constexpr std::uint32_t LeafSize = 4;
  std::vector<TreeNode> Nodes; // Nodes[0] is the root (when not empty)
  std::vector<std::uint32_t> Order;

  /**
   * Builds the tree over `count` triangles of 9 coordinates each (stride `stride` doubles
   * between triangles' first coordinates).
   */
  void Build(const double* vertices, std::size_t stride, std::size_t count);

  /**
   * The nodes' boxes in another frame, from the triangles' boxes in it (6 doubles each:
   * x0, x1, y0, y1, z0, z1, triangles in Order): 6 doubles per node, children before parents.
   */
  void Refit(const double* triangleBoxes, std::vector<double>& out) const;
};
}

#endif
