#include "vtkPenumbraGearsTree.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace penumbra_gears
{
//------------------------------------------------------------------------------
// Median splits on the longest axis of the triangles' centroids, breadth by an explicit
// stack; a node's two children are stored next to each other.
void Tree::Build(const double* vertices, std::size_t stride, std::size_t count)
{
  this->Nodes.clear();
  this->Order.resize(count);
  if (count == 0)
  {
    return;
  }
  std::vector<double> centroid(3 * count);
  for (std::size_t t = 0; t < count; ++t)
  {
    this->Order[t] = static_cast<std::uint32_t>(t);
    const double* v = vertices + t * stride;
    for (int c = 0; c < 3; ++c)
    {
      centroid[3 * t + c] = (v[c] + v[3 + c] + v[6 + c]) / 3.0;
    }
  }
  struct Pending
  {
    std::uint32_t Node, Begin, End;
  };
  this->Nodes.reserve(2 * (count / LeafSize + 1));
  this->Nodes.push_back(TreeNode{});
  std::vector<Pending> stack{ { 0, 0, static_cast<std::uint32_t>(count) } };
  while (!stack.empty())
  {
    const Pending p = stack.back();
    stack.pop_back();
    TreeNode node;
    double cLo[3], cHi[3];
    for (int c = 0; c < 3; ++c)
    {
      node.Lo[c] = cLo[c] = std::numeric_limits<double>::infinity();
      node.Hi[c] = cHi[c] = -std::numeric_limits<double>::infinity();
    }
    for (std::uint32_t i = p.Begin; i < p.End; ++i)
    {
      const std::uint32_t t = this->Order[i];
      const double* v = vertices + t * stride;
      for (int c = 0; c < 3; ++c)
      {
        node.Lo[c] = std::min({ node.Lo[c], v[c], v[3 + c], v[6 + c] });
        node.Hi[c] = std::max({ node.Hi[c], v[c], v[3 + c], v[6 + c] });
        cLo[c] = std::min(cLo[c], centroid[3 * t + c]);
        cHi[c] = std::max(cHi[c], centroid[3 * t + c]);
      }
    }
    if (p.End - p.Begin <= LeafSize)
    {
      node.First = p.Begin;
      node.Count = p.End - p.Begin;
      this->Nodes[p.Node] = node;
      continue;
    }
    int axis = 0;
    for (int c = 1; c < 3; ++c)
    {
      axis = cHi[c] - cLo[c] > cHi[axis] - cLo[axis] ? c : axis;
    }
    const std::uint32_t mid = p.Begin + (p.End - p.Begin) / 2;
    std::nth_element(this->Order.begin() + p.Begin, this->Order.begin() + mid,
      this->Order.begin() + p.End,
      [&](std::uint32_t a, std::uint32_t b)
      {
        return centroid[3 * a + axis] < centroid[3 * b + axis] ||
          (centroid[3 * a + axis] == centroid[3 * b + axis] && a < b);
      });
    node.First = static_cast<std::uint32_t>(this->Nodes.size());
    node.Count = 0;
    this->Nodes[p.Node] = node;
    this->Nodes.push_back(TreeNode{});
    this->Nodes.push_back(TreeNode{});
    stack.push_back({ node.First, p.Begin, mid });
    stack.push_back({ node.First + 1, mid, p.End });
  }
}

//------------------------------------------------------------------------------
// Children are stored after their parent, so one backward pass sees every child first.
void Tree::Refit(const double* triangleBoxes, std::vector<double>& out) const
{
  out.resize(6 * this->Nodes.size());
  for (std::size_t n = this->Nodes.size(); n-- > 0;)
  {
    const TreeNode& node = this->Nodes[n];
    double* box = &out[6 * n];
    const double* first = node.Count > 0
      ? triangleBoxes + 6 * static_cast<std::size_t>(this->Order[node.First])
      : &out[6 * static_cast<std::size_t>(node.First)];
    std::copy(first, first + 6, box);
    const std::uint32_t parts = node.Count > 0 ? node.Count : 2;
    for (std::uint32_t i = 1; i < parts; ++i)
    {
      const double* part = node.Count > 0
        ? triangleBoxes + 6 * static_cast<std::size_t>(this->Order[node.First + i])
        : &out[6 * static_cast<std::size_t>(node.First + i)];
      for (int a = 0; a < 3; ++a)
      {
        box[2 * a] = std::min(box[2 * a], part[2 * a]);
        box[2 * a + 1] = std::max(box[2 * a + 1], part[2 * a + 1]);
      }
    }
  }
}
}
