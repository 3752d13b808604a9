/**
 * @file    vtkPenumbraSceneCutouts.h
 * @brief   Internal to Penumbra::Scene (not installed, not wrapped): where a surface is not
 *          drawn because its alpha is 0.
 *
 * VTK 9.1's polydata fragment shader discards every fragment whose final alpha is <= 0
 * (vtkPolyDataFS.glsl, after texturing). The final alpha is the property's opacity times
 * the scalar colour's alpha times the actor texture's alpha (vtkOpenGLPolyDataMapper::
 * ReplaceShaderColor and ReplaceShaderTCoord), so a point of a surface is drawn, and casts,
 * exactly where each factor is positive:
 * - ScalarAlpha: per point or per cell, whether the mapper's scalar colours (vtkMapper::
 *   MapScalars' rule: the array's own lookup table or the mapper's, the mapper's range unless
 *   UseLookupTableScalarRange, ColorMode, ArrayComponent) have alpha 0. A triangle whose
 *   three point colours (or whose cell colour) have alpha 0 is transparent everywhere; one
 *   with a single positive corner is drawn in its whole interior (the colour is interpolated).
 * - AlphaGrid: the texel alphas of an actor texture, as vtkOpenGLTexture uploads them, and
 *   the exact region of texture space where the sampled alpha is positive: with nearest
 *   filtering the union of the texel squares whose alpha is positive; with linear filtering
 *   the union of the cells of the texel-centre grid with at least one corner of positive
 *   alpha (bilinear weights are all positive inside a cell). Wrap modes repeat, mirror or
 *   clamp the grid (ClampToBorder uses the border colour's alpha).
 */

#ifndef vtkPenumbraSceneCutouts_h
#define vtkPenumbraSceneCutouts_h

#include "vtkPenumbraSceneCasters.h"

#include "vtkType.h"

#include <string>
#include <vector>

class vtkDataSet;
class vtkMapper;
class vtkTexture;

namespace penumbra_scene
{
/**
 * Which points (or cells) of a dataset the mapper colours with alpha 0; empty when scalar
 * colouring is off, interpolated through a colour texture (InterpolateScalarsBeforeMapping:
 * not cut), or never transparent.
 */
struct ScalarAlpha
{
  std::vector<unsigned char> Zero; // 1 where alpha is 0
  bool Cells = false;              // per cell (cell ids of the dataset) instead of per point

  bool Any() const { return !this->Zero.empty(); }
  /// Reads the colours `mapper` gives `data` (the mapper itself is left unchanged).
  void Compute(vtkMapper* mapper, vtkDataSet* data);
};

/**
 * The alpha of an actor texture as a grid of cells in texture space (see the file
 * description). Cell coordinates: x = s * width - o, y = t * height - o with o = 0 for
 * nearest and 1/2 for linear filtering; cell (i, j) is [i, i+1] x [j, j+1].
 */
class AlphaGrid
{
public:
  /**
   * Reads `texture`'s image. Returns false with `why` set when the alpha cannot be
   * reproduced (the caller then casts the whole surface and says so); `HasCutouts()` is
   * false when no texel (nor, with ClampToBorder, the border) has alpha 0.
   */
  bool Build(vtkTexture* texture, std::string& why);

  bool HasCutouts() const { return this->Cutouts; }

  /// Texture coordinates (s, t) to cell coordinates.
  void ToCells(double s, double t, double xy[2]) const;

  enum class Cut
  {
    Whole,  // drawn everywhere
    None,   // drawn nowhere
    Pieces, // drawn on `pieces` only
    TooFine // more cells than `budget` allowed: the caller keeps it whole
  };

  /**
   * The drawn part of a triangle whose corners sit at cell coordinates xy[k], as convex
   * polygons in the triangle's barycentric coordinates. `budget` (cells examined) is
   * decremented.
   */
  Cut CutTriangle(const double xy[3][2], std::vector<BaryPolygon>& pieces, long long& budget) const;

private:
  struct Axis
  {
    int Texels = 1;
    int Wrap = 0;
    long long Length = 1; // canonical cells
    long long Canon(long long cell) const;
    long long Representative(long long canon) const;
    int Texel(long long index) const; // -1: the border
    // Up to two canonical intervals covering the cells [k0, k1]; returns their number.
    int Intervals(long long k0, long long k1, long long out[2][2]) const;
  };

  bool TexelDrawn(int i, int j) const;
  bool CellDrawn(long long ci, long long cj) const; // canonical indices
  long long Count(long long i0, long long i1, long long j0, long long j1) const; // canonical
  // Drawn cells / cells of the canonical classes met by [k0, k1] x [l0, l1].
  void Classes(long long k0, long long k1, long long l0, long long l1, long long& drawn,
    long long& total) const;
  Cut CutDegenerate(
    const double xy[3][2], std::vector<BaryPolygon>& pieces, long long& budget) const;

  bool Cutouts = false;
  bool Linear = false;
  bool BorderDrawn = true;
  Axis X, Y;
  std::vector<unsigned char> Alpha; // texel alpha > 0, row-major
  std::vector<unsigned char> Drawn; // canonical cells
  std::vector<long long> Sum;       // summed-area table of Drawn, (Lx + 1) * (Ly + 1)
};
}

#endif
