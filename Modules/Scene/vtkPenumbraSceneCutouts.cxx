#include "vtkPenumbraSceneCutouts.h"

#include "vtkAbstractArray.h"
#include "vtkAbstractMapper.h"
#include "vtkAlgorithm.h"
#include "vtkDataArray.h"
#include "vtkDataSet.h"
#include "vtkImageData.h"
#include "vtkLookupTable.h"
#include "vtkMapper.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkScalarsToColors.h"
#include "vtkSmartPointer.h"
#include "vtkTexture.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>

namespace penumbra_scene
{
namespace
{
// vtkMapper keeps its lookup table protected and GetLookupTable() creates a default one,
// which changes the mapper's MTime; reading the member leaves the mapper as it is.
struct MapperAccess : vtkMapper
{
  static vtkScalarsToColors* vtkMapper::*Table() { return &MapperAccess::LookupTable; }
};

// A canonical table larger than this (cells) is not built: the texture is cast whole.
constexpr long long MaxTableCells = 64ll << 20;

long long FloorMod(long long a, long long n)
{
  const long long r = a % n;
  return r < 0 ? r + n : r;
}

// The mapped RGBA colours of `scalars` (4 components) through `lut` as vtkMapper::MapScalars
// and vtkTexture::MapScalarsToColors do: direct colours stay as they are.
vtkSmartPointer<vtkUnsignedCharArray> MapColors(
  vtkScalarsToColors* lut, vtkDataArray* scalars, int colorMode, int component)
{
  vtkSmartPointer<vtkUnsignedCharArray> colors;
  colors.TakeReference(lut->MapScalars(scalars, colorMode, component));
  return colors;
}
}

//------------------------------------------------------------------------------
void ScalarAlpha::Compute(vtkMapper* mapper, vtkDataSet* data)
{
  this->Zero.clear();
  this->Cells = false;
  if (!mapper || !data || !mapper->GetScalarVisibility())
  {
    return;
  }
  int cellFlag = 0;
  vtkAbstractArray* abstract = vtkAbstractMapper::GetAbstractScalars(data, mapper->GetScalarMode(),
    mapper->GetArrayAccessMode(), mapper->GetArrayId(), mapper->GetArrayName(), cellFlag);
  auto* scalars = vtkDataArray::SafeDownCast(abstract);
  if (!scalars || scalars->GetNumberOfTuples() == 0 || cellFlag == 2)
  {
    return; // no colours, non-numeric (indexed) or field data: not cut
  }
  // vtkMapper::MapScalars: the array's own table, else the mapper's (a default one, opaque,
  // when there is none: then only direct colours can carry alpha).
  vtkScalarsToColors* table = scalars->GetLookupTable();
  if (!table)
  {
    table = mapper->*MapperAccess::Table();
  }
  vtkSmartPointer<vtkScalarsToColors> lut;
  if (table)
  {
    lut.TakeReference(table->NewInstance());
    lut->DeepCopy(table);
  }
  else
  {
    lut = vtkSmartPointer<vtkLookupTable>::New();
  }
  lut->Build();
  if (!mapper->GetUseLookupTableScalarRange())
  {
    lut->SetRange(mapper->GetScalarRange());
  }
  // Point scalars interpolated before mapping go through a colour texture: not cut.
  const bool direct = (mapper->GetColorMode() == VTK_COLOR_MODE_DEFAULT &&
                        scalars->GetDataType() == VTK_UNSIGNED_CHAR) ||
    mapper->GetColorMode() == VTK_COLOR_MODE_DIRECT_SCALARS;
  if (mapper->GetInterpolateScalarsBeforeMapping() && cellFlag == 0 && !direct &&
    !lut->GetIndexedLookup())
  {
    return;
  }
  lut->SetAlpha(1.0);
  const int component = scalars->GetNumberOfComponents() <= mapper->GetArrayComponent()
    ? 0
    : mapper->GetArrayComponent();
  if (lut->IsOpaque(scalars, mapper->GetColorMode(), component))
  {
    return; // VTK's own test: no colour is translucent, none has alpha 0
  }
  vtkSmartPointer<vtkUnsignedCharArray> colors =
    MapColors(lut, scalars, mapper->GetColorMode(), component);
  const vtkIdType expected = cellFlag == 1 ? data->GetNumberOfCells() : data->GetNumberOfPoints();
  if (!colors || colors->GetNumberOfComponents() != 4 || colors->GetNumberOfTuples() != expected)
  {
    return; // not one colour per point (cell): not what the mapper can draw either
  }
  const vtkIdType n = colors->GetNumberOfTuples();
  const unsigned char* rgba = colors->GetPointer(0);
  bool any = false;
  std::vector<unsigned char> zero(static_cast<size_t>(n), 0);
  for (vtkIdType i = 0; i < n; ++i)
  {
    zero[static_cast<size_t>(i)] = rgba[4 * i + 3] == 0 ? 1 : 0;
    any = any || zero[static_cast<size_t>(i)];
  }
  if (any)
  {
    this->Zero.swap(zero);
    this->Cells = cellFlag == 1;
  }
}

//------------------------------------------------------------------------------
long long AlphaGrid::Axis::Canon(long long cell) const
{
  switch (this->Wrap)
  {
    case vtkTexture::Repeat:
    case vtkTexture::MirroredRepeat:
      return FloorMod(cell, this->Length);
    default:
      // Clamped: every cell left of -2 (right of Texels) reads the same texels as -2 (Texels).
      return std::min<long long>(std::max<long long>(cell, -2), this->Texels) + 2;
  }
}

//------------------------------------------------------------------------------
long long AlphaGrid::Axis::Representative(long long canon) const
{
  return this->Wrap == vtkTexture::Repeat || this->Wrap == vtkTexture::MirroredRepeat ? canon
                                                                                      : canon - 2;
}

//------------------------------------------------------------------------------
int AlphaGrid::Axis::Texel(long long index) const
{
  const long long n = this->Texels;
  switch (this->Wrap)
  {
    case vtkTexture::Repeat:
      return static_cast<int>(FloorMod(index, n));
    case vtkTexture::MirroredRepeat:
    {
      const long long m = FloorMod(index, 2 * n);
      return static_cast<int>(m < n ? m : 2 * n - 1 - m);
    }
    case vtkTexture::ClampToBorder:
      return index < 0 || index >= n ? -1 : static_cast<int>(index);
    default: // ClampToEdge
      return static_cast<int>(std::min(std::max(index, 0ll), n - 1));
  }
}

//------------------------------------------------------------------------------
int AlphaGrid::Axis::Intervals(long long k0, long long k1, long long out[2][2]) const
{
  if (this->Wrap == vtkTexture::Repeat || this->Wrap == vtkTexture::MirroredRepeat)
  {
    if (k1 - k0 + 1 >= this->Length)
    {
      out[0][0] = 0;
      out[0][1] = this->Length - 1;
      return 1;
    }
    const long long c0 = this->Canon(k0);
    const long long c1 = c0 + (k1 - k0);
    out[0][0] = c0;
    if (c1 < this->Length)
    {
      out[0][1] = c1;
      return 1;
    }
    out[0][1] = this->Length - 1;
    out[1][0] = 0;
    out[1][1] = c1 - this->Length;
    return 2;
  }
  out[0][0] = this->Canon(k0);
  out[0][1] = this->Canon(k1);
  return 1;
}

//------------------------------------------------------------------------------
bool AlphaGrid::TexelDrawn(int i, int j) const
{
  if (i < 0 || j < 0)
  {
    return this->BorderDrawn;
  }
  return this->Alpha[static_cast<size_t>(j) * this->X.Texels + i] != 0;
}

//------------------------------------------------------------------------------
bool AlphaGrid::CellDrawn(long long ci, long long cj) const
{
  return this->Drawn[static_cast<size_t>(cj * this->X.Length + ci)] != 0;
}

//------------------------------------------------------------------------------
long long AlphaGrid::Count(long long i0, long long i1, long long j0, long long j1) const
{
  const long long w = this->X.Length + 1;
  auto at = [&](long long i, long long j) { return this->Sum[static_cast<size_t>(j * w + i)]; };
  return at(i1 + 1, j1 + 1) - at(i0, j1 + 1) - at(i1 + 1, j0) + at(i0, j0);
}

//------------------------------------------------------------------------------
void AlphaGrid::Classes(
  long long k0, long long k1, long long l0, long long l1, long long& drawn, long long& total) const
{
  long long xs[2][2], ys[2][2];
  const int nx = this->X.Intervals(k0, k1, xs);
  const int ny = this->Y.Intervals(l0, l1, ys);
  drawn = total = 0;
  for (int a = 0; a < nx; ++a)
  {
    for (int b = 0; b < ny; ++b)
    {
      drawn += this->Count(xs[a][0], xs[a][1], ys[b][0], ys[b][1]);
      total += (xs[a][1] - xs[a][0] + 1) * (ys[b][1] - ys[b][0] + 1);
    }
  }
}

//------------------------------------------------------------------------------
bool AlphaGrid::Build(vtkTexture* texture, std::string& why)
{
  *this = AlphaGrid();
  // vtkOpenGLPolyDataMapper::ReplaceShaderTCoord ignores cube maps; an image without scalars
  // is not loaded (vtkOpenGLTexture::Load reports it): nothing modulates the alpha then.
  if (!texture || texture->GetCubeMap())
  {
    return true;
  }
  if (texture->GetNumberOfInputConnections(0) > 0)
  {
    texture->GetInputAlgorithm()->Update();
  }
  vtkImageData* image = texture->GetInput();
  vtkDataArray* scalars = image ? image->GetPointData()->GetScalars() : nullptr;
  if (!scalars || scalars->GetNumberOfTuples() == 0)
  {
    return true;
  }
  if (scalars->GetNumberOfTuples() != image->GetNumberOfPoints())
  {
    why = "texture scalars are not one per image point";
    return false;
  }
  // vtkOpenGLTexture::Load: a 2D image in any axis-aligned plane; 3D images are refused.
  int dims[3];
  image->GetDimensions(dims);
  int size[2];
  if (dims[0] == 1)
  {
    size[0] = dims[1];
    size[1] = dims[2];
  }
  else if (dims[1] == 1 || dims[2] == 1)
  {
    size[0] = dims[0];
    size[1] = dims[1] == 1 ? dims[2] : dims[1];
  }
  else
  {
    return true; // not loaded, not applied
  }

  // The colours as uploaded: unsigned char with 3 or 4 components directly (unless
  // ColorModeToMapScalars), everything else through the texture's table (a default one over
  // the scalar range when it has none), vtkTexture::MapScalarsToColors.
  std::vector<unsigned char> alpha(static_cast<size_t>(scalars->GetNumberOfTuples()), 1);
  const int comps = scalars->GetNumberOfComponents();
  const bool direct = texture->GetColorMode() != VTK_COLOR_MODE_MAP_SCALARS &&
    scalars->GetDataType() == VTK_UNSIGNED_CHAR && comps >= 3;
  if (direct)
  {
    if (comps == 4)
    {
      for (vtkIdType i = 0; i < scalars->GetNumberOfTuples(); ++i)
      {
        alpha[static_cast<size_t>(i)] = scalars->GetComponent(i, 3) > 0.0 ? 1 : 0;
      }
    }
  }
  else
  {
    vtkSmartPointer<vtkScalarsToColors> lut = texture->GetLookupTable();
    if (!lut)
    {
      auto table = vtkSmartPointer<vtkLookupTable>::New();
      table->Build();
      table->SetRange(scalars->GetRange(0));
      lut = table;
    }
    vtkSmartPointer<vtkUnsignedCharArray> colors =
      MapColors(lut, scalars, texture->GetColorMode(), -1);
    if (!colors || colors->GetNumberOfComponents() != 4)
    {
      why = "texture colours could not be mapped";
      return false;
    }
    for (vtkIdType i = 0; i < colors->GetNumberOfTuples(); ++i)
    {
      alpha[static_cast<size_t>(i)] = colors->GetValue(4 * i + 3) > 0 ? 1 : 0;
    }
  }

  this->Linear = texture->GetInterpolate() != 0;
  const int wrap = texture->GetWrap();
  this->BorderDrawn = texture->GetBorderColor()[3] > 0.0f;
  this->Cutouts = std::find(alpha.begin(), alpha.end(), 0) != alpha.end() ||
    (wrap == vtkTexture::ClampToBorder && !this->BorderDrawn);
  if (!this->Cutouts)
  {
    return true;
  }
  this->Alpha.swap(alpha);
  Axis* axes[2] = { &this->X, &this->Y };
  for (int a = 0; a < 2; ++a)
  {
    Axis& axis = *axes[a];
    axis.Texels = size[a];
    axis.Wrap = wrap;
    axis.Length = wrap == vtkTexture::Repeat ? size[a]
      : wrap == vtkTexture::MirroredRepeat   ? 2ll * size[a]
                                             : size[a] + 3ll;
  }
  if (this->X.Length * this->Y.Length > MaxTableCells)
  {
    why = "texture too large to cut out (" + std::to_string(size[0]) + " x " +
      std::to_string(size[1]) + ")";
    this->Cutouts = false;
    return false;
  }
  const long long lx = this->X.Length, ly = this->Y.Length;
  this->Drawn.assign(static_cast<size_t>(lx * ly), 0);
  this->Sum.assign(static_cast<size_t>((lx + 1) * (ly + 1)), 0);
  for (long long cj = 0; cj < ly; ++cj)
  {
    const long long j = this->Y.Representative(cj);
    for (long long ci = 0; ci < lx; ++ci)
    {
      const long long i = this->X.Representative(ci);
      bool drawn = this->TexelDrawn(this->X.Texel(i), this->Y.Texel(j));
      if (this->Linear) // the cell between texel centres i, i+1 and j, j+1
      {
        drawn = drawn || this->TexelDrawn(this->X.Texel(i + 1), this->Y.Texel(j)) ||
          this->TexelDrawn(this->X.Texel(i), this->Y.Texel(j + 1)) ||
          this->TexelDrawn(this->X.Texel(i + 1), this->Y.Texel(j + 1));
      }
      this->Drawn[static_cast<size_t>(cj * lx + ci)] = drawn ? 1 : 0;
      this->Sum[static_cast<size_t>((cj + 1) * (lx + 1) + ci + 1)] = (drawn ? 1 : 0) +
        this->Sum[static_cast<size_t>(cj * (lx + 1) + ci + 1)] +
        this->Sum[static_cast<size_t>((cj + 1) * (lx + 1) + ci)] -
        this->Sum[static_cast<size_t>(cj * (lx + 1) + ci)];
    }
  }
  return true;
}

//------------------------------------------------------------------------------
void AlphaGrid::ToCells(double s, double t, double xy[2]) const
{
  const double o = this->Linear ? 0.5 : 0.0;
  xy[0] = s * this->X.Texels - o;
  xy[1] = t * this->Y.Texels - o;
}

namespace
{
// Corner values of the linear function `sign` * (coordinate `axis` - at) on the triangle.
void AxisCorners(const double xy[3][2], int axis, double at, double sign, double f[3])
{
  for (int k = 0; k < 3; ++k)
  {
    f[k] = sign * (xy[k][axis] - at);
  }
}
}

//------------------------------------------------------------------------------
AlphaGrid::Cut AlphaGrid::CutTriangle(
  const double xy[3][2], std::vector<BaryPolygon>& pieces, long long& budget) const
{
  pieces.clear();
  const double e1[2] = { xy[1][0] - xy[0][0], xy[1][1] - xy[0][1] };
  const double e2[2] = { xy[2][0] - xy[0][0], xy[2][1] - xy[0][1] };
  const double e3[2] = { xy[2][0] - xy[1][0], xy[2][1] - xy[1][1] };
  const double longest = std::max({ e1[0] * e1[0] + e1[1] * e1[1], e2[0] * e2[0] + e2[1] * e2[1],
    e3[0] * e3[0] + e3[1] * e3[1] });
  const double cross = e1[0] * e2[1] - e1[1] * e2[0];
  if (!(std::fabs(cross) > 1e-12 * longest))
  {
    return this->CutDegenerate(xy, pieces, budget);
  }
  // Cells [k0, k1] x [l0, l1] meet the triangle's box with positive area.
  const double x0 = std::min({ xy[0][0], xy[1][0], xy[2][0] });
  const double x1 = std::max({ xy[0][0], xy[1][0], xy[2][0] });
  const double y0 = std::min({ xy[0][1], xy[1][1], xy[2][1] });
  const double y1 = std::max({ xy[0][1], xy[1][1], xy[2][1] });
  const long long k0 = static_cast<long long>(std::floor(x0));
  const long long k1 = std::max(k0, static_cast<long long>(std::ceil(x1)) - 1);
  const long long l0 = static_cast<long long>(std::floor(y0));
  const long long l1 = std::max(l0, static_cast<long long>(std::ceil(y1)) - 1);

  // Quadtree over the cells: a block wholly drawn or wholly cut decides its part of the
  // triangle at once, a mixed one is split along its longer side.
  struct Block
  {
    long long K0, K1, L0, L1;
    BaryPolygon Part;
  };
  std::vector<Block> stack;
  stack.push_back({ k0, k1, l0, l1, WholeTriangle() });
  BaryPolygon scratch;
  bool cut = false; // some part of the triangle lies in cells drawn nowhere
  while (!stack.empty())
  {
    Block b = std::move(stack.back());
    stack.pop_back();
    if (b.Part.size() < 3)
    {
      continue; // the triangle does not reach this block
    }
    if (--budget < 0)
    {
      pieces.clear();
      return Cut::TooFine;
    }
    long long drawn = 0, total = 0;
    this->Classes(b.K0, b.K1, b.L0, b.L1, drawn, total);
    if (drawn == total)
    {
      pieces.push_back(std::move(b.Part));
      continue;
    }
    if (drawn == 0)
    {
      cut = true;
      continue;
    }
    const bool alongX = b.K1 - b.K0 >= b.L1 - b.L0;
    const long long mid = alongX ? b.K0 + (b.K1 - b.K0) / 2 : b.L0 + (b.L1 - b.L0) / 2;
    double f[3];
    Block low = { b.K0, alongX ? mid : b.K1, b.L0, alongX ? b.L1 : mid, b.Part };
    AxisCorners(xy, alongX ? 0 : 1, static_cast<double>(mid + 1), -1.0, f);
    ClipBary(low.Part, f, scratch);
    Block high = { alongX ? mid + 1 : b.K0, b.K1, alongX ? b.L0 : mid + 1, b.L1,
      std::move(b.Part) };
    AxisCorners(xy, alongX ? 0 : 1, static_cast<double>(mid + 1), 1.0, f);
    ClipBary(high.Part, f, scratch);
    stack.push_back(std::move(low));
    stack.push_back(std::move(high));
  }
  if (!cut)
  {
    pieces.clear();
    return Cut::Whole;
  }
  return pieces.empty() ? Cut::None : Cut::Pieces;
}

//------------------------------------------------------------------------------
AlphaGrid::Cut AlphaGrid::CutDegenerate(
  const double xy[3][2], std::vector<BaryPolygon>& pieces, long long& budget) const
{
  // The texture coordinates of the triangle lie on a segment A -> B (or a point): the alpha
  // is a function of u = (x - A) . (B - A) / |B - A|^2 alone, linear on the triangle.
  int ia = 0, ib = 0;
  double best = -1.0;
  for (int p = 0; p < 3; ++p)
  {
    for (int q = p + 1; q < 3; ++q)
    {
      const double dx = xy[q][0] - xy[p][0], dy = xy[q][1] - xy[p][1];
      if (dx * dx + dy * dy > best)
      {
        best = dx * dx + dy * dy;
        ia = p;
        ib = q;
      }
    }
  }
  const double a[2] = { xy[ia][0], xy[ia][1] };
  const double d[2] = { xy[ib][0] - a[0], xy[ib][1] - a[1] };
  auto drawnAt = [this](double x, double y)
  {
    const long long i = static_cast<long long>(std::floor(x));
    const long long j = static_cast<long long>(std::floor(y));
    return this->CellDrawn(this->X.Canon(i), this->Y.Canon(j));
  };
  if (!(best > 0.0))
  {
    return drawnAt(a[0], a[1]) ? Cut::Whole : Cut::None;
  }
  // Split u at every crossing of a cell boundary; each interval has one cell.
  std::vector<double> splits = { 0.0, 1.0 };
  for (int axis = 0; axis < 2; ++axis)
  {
    if (d[axis] == 0.0)
    {
      continue;
    }
    const double lo = std::min(a[axis], a[axis] + d[axis]);
    const double hi = std::max(a[axis], a[axis] + d[axis]);
    const long long first = static_cast<long long>(std::ceil(lo));
    const long long last = static_cast<long long>(std::floor(hi));
    budget -= std::max(0ll, last - first + 1);
    if (budget < 0)
    {
      return Cut::TooFine;
    }
    for (long long g = first; g <= last; ++g)
    {
      splits.push_back((static_cast<double>(g) - a[axis]) / d[axis]);
    }
  }
  std::sort(splits.begin(), splits.end());
  double f[3];
  for (int k = 0; k < 3; ++k)
  {
    f[k] = ((xy[k][0] - a[0]) * d[0] + (xy[k][1] - a[1]) * d[1]) / best;
  }
  BaryPolygon scratch;
  bool cut = false;
  for (size_t s = 0; s + 1 < splits.size(); ++s)
  {
    size_t e = s;
    while (e + 1 < splits.size() &&
      drawnAt(a[0] + 0.5 * (splits[e] + splits[e + 1]) * d[0],
        a[1] + 0.5 * (splits[e] + splits[e + 1]) * d[1]))
    {
      ++e;
    }
    if (e == s)
    {
      cut = cut || splits[s + 1] > splits[s];
      continue;
    }
    // u in [splits[s], splits[e]] is drawn.
    BaryPolygon part = WholeTriangle();
    const double lo[3] = { f[0] - splits[s], f[1] - splits[s], f[2] - splits[s] };
    const double hi[3] = { splits[e] - f[0], splits[e] - f[1], splits[e] - f[2] };
    ClipBary(part, lo, scratch);
    ClipBary(part, hi, scratch);
    if (part.size() >= 3)
    {
      pieces.push_back(std::move(part));
    }
    s = e - 1;
  }
  if (!cut)
  {
    pieces.clear();
    return Cut::Whole;
  }
  return pieces.empty() ? Cut::None : Cut::Pieces;
}
}
