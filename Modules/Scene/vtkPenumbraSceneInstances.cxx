#include "vtkPenumbraSceneInstances.h"

#include "vtkPenumbraSceneCutouts.h"

#include "vtkBitArray.h"
#include "vtkCellArray.h"
#include "vtkCompositeDataDisplayAttributes.h"
#include "vtkCompositeDataIterator.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataArray.h"
#include "vtkGlyph3DMapper.h"
#include "vtkImageData.h"
#include "vtkImageProperty.h"
#include "vtkImageSlice.h"
#include "vtkImageSliceMapper.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkPointGaussianMapper.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkQuaternion.h"
#include "vtkScalarsToColors.h"
#include "vtkSmartPointer.h"

#include <cmath>
#include <functional>

namespace penumbra_scene
{
namespace
{
// vtkGlyph3DMapper's array getters are protected; they hold VTK's own rules (the flags that
// switch each array off, the point association), so they are called rather than copied.
struct GlyphAccess : vtkGlyph3DMapper
{
  using Getter = vtkDataArray* (vtkGlyph3DMapper::*)(vtkDataSet*);
  static Getter Mask() { return &GlyphAccess::GetMaskArray; }
  static Getter Orientation() { return &GlyphAccess::GetOrientationArray; }
  static Getter Scale() { return &GlyphAccess::GetScaleArray; }
  static Getter SourceIndex() { return &GlyphAccess::GetSourceIndexArray; }
};

// Calls `visit` for each dataset of `data` that is drawn: the dataset itself, or the leaves
// of a composite whose display attributes do not hide them.
void ForEachDataSet(vtkDataObject* data, vtkCompositeDataDisplayAttributes* attributes,
  const std::function<void(vtkDataSet*)>& visit)
{
  if (auto* ds = vtkDataSet::SafeDownCast(data))
  {
    visit(ds);
    return;
  }
  auto* composite = vtkCompositeDataSet::SafeDownCast(data);
  if (!composite)
  {
    return;
  }
  vtkSmartPointer<vtkCompositeDataIterator> it;
  it.TakeReference(composite->NewIterator());
  it->SkipEmptyNodesOn();
  for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem())
  {
    vtkDataObject* leaf = it->GetCurrentDataObject();
    const bool visible = attributes && attributes->HasBlockVisibility(leaf)
      ? attributes->GetBlockVisibility(leaf)
      : true;
    if (visible && vtkDataSet::SafeDownCast(leaf))
    {
      visit(vtkDataSet::SafeDownCast(leaf));
    }
  }
}

// The unit line along x VTK glyphs with when the mapper has no source.
vtkSmartPointer<vtkPolyData> DefaultGlyphSource()
{
  auto source = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  points->InsertNextPoint(0, 0, 0);
  points->InsertNextPoint(1, 0, 0);
  source->SetPoints(points);
  vtkNew<vtkCellArray> lines;
  const vtkIdType ids[2] = { 0, 1 };
  lines->InsertNextCell(2, ids);
  source->SetLines(lines);
  return source;
}

// The instance matrix of point `id` (row-major), as vtkOpenGLGlyph3DMapper builds it.
void InstanceMatrix(vtkGlyph3DMapper* mapper, vtkDataSet* ds, vtkIdType id, vtkDataArray* orient,
  vtkDataArray* scale, double trans[16])
{
  const double* range = mapper->GetRange();
  const double den = range[1] - range[0] == 0.0 ? 1.0 : range[1] - range[0];
  double sx = 1.0, sy = 1.0, sz = 1.0;
  if (scale)
  {
    const double* tuple = scale->GetTuple(id);
    if (mapper->GetScaleMode() == vtkGlyph3DMapper::SCALE_BY_MAGNITUDE)
    {
      sx = sy = sz = vtkMath::Norm(tuple, scale->GetNumberOfComponents());
    }
    else if (mapper->GetScaleMode() == vtkGlyph3DMapper::SCALE_BY_COMPONENTS &&
      scale->GetNumberOfComponents() == 3)
    {
      sx = tuple[0];
      sy = tuple[1];
      sz = tuple[2];
    }
    if (mapper->GetClamping() && mapper->GetScaleMode() != vtkGlyph3DMapper::NO_DATA_SCALING)
    {
      for (double* s : { &sx, &sy, &sz })
      {
        *s = (std::min(std::max(*s, range[0]), range[1]) - range[0]) / den;
      }
    }
  }
  sx *= mapper->GetScaleFactor();
  sy *= mapper->GetScaleFactor();
  sz *= mapper->GetScaleFactor();

  vtkMatrix4x4::Identity(trans);
  double x[3];
  ds->GetPoint(id, x);
  trans[3] = x[0];
  trans[7] = x[1];
  trans[11] = x[2];
  if (orient)
  {
    double o[4] = { 0, 0, 0, 0 };
    orient->GetTuple(id, o);
    vtkQuaterniond q;
    switch (mapper->GetOrientationMode())
    {
      case vtkGlyph3DMapper::ROTATION:
      {
        auto axis = [](double degrees, int k)
        {
          const double a = vtkMath::RadiansFromDegrees(degrees);
          double v[4] = { std::cos(0.5 * a), 0, 0, 0 };
          v[k + 1] = std::sin(0.5 * a);
          return vtkQuaterniond(v);
        };
        q = axis(o[2], 2) * axis(o[0], 0) * axis(o[1], 1);
        break;
      }
      case vtkGlyph3DMapper::DIRECTION:
        if (o[1] == 0.0 && o[2] == 0.0)
        {
          if (o[0] < 0)
          {
            q.Set(0.0, 0.0, 1.0, 0.0);
          }
        }
        else
        {
          const double mag = vtkMath::Norm(o);
          double v[3] = { (o[0] + mag) / 2.0, o[1] / 2.0, o[2] / 2.0 };
          const double f = 1.0 / std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
          q.Set(0.0, v[0] * f, v[1] * f, v[2] * f);
        }
        break;
      default: // QUATERNION
        q.Set(o);
        break;
    }
    double r[3][3];
    q.ToMatrix3x3(r);
    for (int i = 0; i < 3; ++i)
    {
      for (int j = 0; j < 3; ++j)
      {
        trans[4 * i + j] = r[i][j];
      }
    }
  }
  if (mapper->GetScaling())
  {
    sx = sx == 0.0 ? 1.0e-10 : sx;
    sy = sy == 0.0 ? 1.0e-10 : sy;
    sz = sz == 0.0 ? 1.0e-10 : sz;
    for (int i = 0; i < 3; ++i)
    {
      trans[4 * i] *= sx;
      trans[4 * i + 1] *= sy;
      trans[4 * i + 2] *= sz;
    }
  }
}

void GlyphDataSet(vtkGlyph3DMapper* mapper, vtkDataSet* ds, const double m[16],
  const DrawStyle& style, TriangleList& drawn, TriangleList& casters, Outcome& outcome)
{
  const vtkIdType n = ds->GetNumberOfPoints();
  vtkDataArray* maskData = (mapper->*GlyphAccess::Mask())(ds);
  auto* mask = vtkBitArray::SafeDownCast(maskData);
  vtkDataArray* orient = (mapper->*GlyphAccess::Orientation())(ds);
  const int orientComps = mapper->GetOrientationMode() == vtkGlyph3DMapper::QUATERNION ? 4 : 3;
  if ((mask && mask->GetNumberOfComponents() != 1) ||
    (orient && orient->GetNumberOfComponents() != orientComps))
  {
    return; // VTK reports the array and draws nothing
  }
  vtkDataArray* index = (mapper->*GlyphAccess::SourceIndex())(ds);
  vtkDataArray* scale = (mapper->*GlyphAccess::Scale())(ds);
  std::vector<vtkSmartPointer<vtkPolyData>> sources;
  if (!mapper->GetSource(0))
  {
    sources.push_back(DefaultGlyphSource());
  }
  else
  {
    for (int i = 0; i < mapper->GetNumberOfInputConnections(1); ++i)
    {
      sources.emplace_back(mapper->GetSource(i));
    }
  }
  ScalarAlpha alpha;
  alpha.Compute(mapper, ds);
  const int entries = static_cast<int>(sources.size());
  for (vtkIdType id = 0; id < n; ++id)
  {
    if ((mask && mask->GetValue(id) == 0) ||
      (alpha.Any() && !alpha.Cells && alpha.Zero[static_cast<size_t>(id)]))
    {
      continue;
    }
    int which = 0;
    if (index)
    {
      const double value = vtkMath::Norm(index->GetTuple(id), index->GetNumberOfComponents());
      which = vtkMath::ClampValue(static_cast<int>(value), 0, entries - 1);
    }
    vtkPolyData* source = sources[static_cast<size_t>(which)];
    if (!source)
    {
      continue;
    }
    double trans[16], world[16];
    InstanceMatrix(mapper, ds, id, orient, scale, trans);
    vtkMatrix4x4::Multiply4x4(m, trans, world);
    const vtkIdType firstDrawn = drawn.Size(), firstCaster = casters.Size();
    AppendDrawnPolyData(source, world, 0, style, drawn, casters, nullptr, outcome);
    // Cell ids name the input point the instance stands on.
    drawn.CellIds.Fill(firstDrawn, id);
    casters.CellIds.Fill(firstCaster, id);
  }
}
}

//------------------------------------------------------------------------------
void AppendGlyphs(vtkGlyph3DMapper* mapper, vtkDataObject* data, const double m[16],
  const DrawStyle& style, TriangleList& drawn, TriangleList& casters, Outcome& outcome,
  std::string& note)
{
  if (mapper->GetUseSourceTableTree())
  {
    note = "vtkGlyph3DMapper with UseSourceTableTree is not reproduced: casts nothing";
    return;
  }
  for (int i = 0; i < mapper->GetNumberOfInputConnections(1); ++i)
  {
    if (!mapper->GetStatic() && mapper->GetInputAlgorithm(1, i))
    {
      mapper->GetInputAlgorithm(1, i)->Update();
    }
  }
  ForEachDataSet(data, mapper->GetBlockAttributes(),
    [&](vtkDataSet* ds) { GlyphDataSet(mapper, ds, m, style, drawn, casters, outcome); });
}

namespace
{
// The splat radius of point `id` before ScaleFactor and TriangleScale (the helper's rule).
double SplatSize(vtkPointGaussianMapper* mapper, vtkDataArray* sizes, vtkIdType id)
{
  double s = 1.0;
  if (sizes)
  {
    const int comps = sizes->GetNumberOfComponents();
    const int component = comps == 1 ? 0 : mapper->GetScaleArrayComponent();
    if (component < 0 || component >= comps)
    {
      s = vtkMath::Norm(sizes->GetTuple(id), comps);
    }
    else
    {
      s = sizes->GetComponent(id, component);
    }
    if (mapper->GetScaleFunction())
    {
      s = mapper->GetScaleFunction()->GetValue(s);
    }
  }
  return s;
}

void SplatPolyData(vtkPointGaussianMapper* mapper, vtkPolyData* poly, const double m[16],
  const DrawStyle& style, TriangleList& casters, Outcome& outcome)
{
  vtkPoints* points = poly->GetPoints();
  if (!points || points->GetNumberOfPoints() == 0)
  {
    return;
  }
  // Splat centres: the vertex cells' point ids in order, or every point.
  std::vector<vtkIdType> centres;
  vtkCellArray* verts = poly->GetVerts();
  if (verts->GetNumberOfCells() > 0)
  {
    vtkIdType npts = 0;
    const vtkIdType* ids = nullptr;
    for (verts->InitTraversal(); verts->GetNextCell(npts, ids);)
    {
      centres.insert(centres.end(), ids, ids + npts);
    }
  }
  else
  {
    centres.resize(static_cast<size_t>(points->GetNumberOfPoints()));
    for (size_t i = 0; i < centres.size(); ++i)
    {
      centres[i] = static_cast<vtkIdType>(i);
    }
  }
  const bool usingPoints = mapper->GetScaleFactor() == 0.0;
  outcome.UsesWidth = outcome.UsesWidth || usingPoints;
  vtkDataArray* sizes =
    mapper->GetScaleArray() ? poly->GetPointData()->GetArray(mapper->GetScaleArray()) : nullptr;
  ScalarAlpha alpha;
  alpha.Compute(mapper, poly);
  std::vector<char> counted(static_cast<size_t>(points->GetNumberOfPoints()), 0);
  for (vtkIdType id : centres)
  {
    if (alpha.Any() && !alpha.Cells && alpha.Zero[static_cast<size_t>(id)])
    {
      continue;
    }
    double p[3], w[3];
    points->GetPoint(id, p);
    TransformPoint(m, p, w);
    const double diameter = usingPoints ? style.PointSize
                                        : 2.0 *
        std::fabs(
          SplatSize(mapper, sizes, id) * mapper->GetScaleFactor() * mapper->GetTriangleScale());
    if (!std::isfinite(w[0]) || !std::isfinite(w[1]) || !std::isfinite(w[2]) ||
      !std::isfinite(diameter))
    {
      outcome.BadPoints += counted[static_cast<size_t>(id)] ? 0 : 1;
      counted[static_cast<size_t>(id)] = 1;
      continue;
    }
    const Vec3 c(w[0], w[1], w[2]);
    if (Inside(style.Clip, c))
    {
      AppendPointSolid(c, diameter, id, casters);
    }
  }
}
}

//------------------------------------------------------------------------------
void AppendSplats(vtkPointGaussianMapper* mapper, vtkDataObject* data, const double m[16],
  const DrawStyle& style, TriangleList& casters, Outcome& outcome, std::string& note)
{
  if (mapper->GetSplatShaderCode() && mapper->GetSplatShaderCode()[0] &&
    mapper->GetScaleFactor() != 0.0)
  {
    note = "vtkPointGaussianMapper with a custom splat shader: splats cast the default "
           "footprint";
  }
  ForEachDataSet(data, nullptr,
    [&](vtkDataSet* ds)
    {
      if (auto* poly = vtkPolyData::SafeDownCast(ds))
      {
        SplatPolyData(mapper, poly, m, style, casters, outcome);
      }
    });
}

//------------------------------------------------------------------------------
void AppendImageSlice(vtkImageSlice* slice, const double m[16], const DrawStyle& style,
  TriangleList& drawn, TriangleList& casters, Outcome& outcome, std::string& note)
{
  auto* mapper = vtkImageSliceMapper::SafeDownCast(slice->GetMapper());
  if (!mapper)
  {
    note = std::string(slice->GetMapper() ? slice->GetMapper()->GetClassName() : "no mapper") +
      ": only vtkImageSliceMapper slices are cast; casts nothing";
    return;
  }
  vtkImageData* image = mapper->GetInput();
  if (!image || image->GetNumberOfPoints() == 0)
  {
    return;
  }
  if (mapper->GetSliceFacesCamera() || mapper->GetSliceAtFocalPoint())
  {
    note = "the displayed slice follows the camera (SliceFacesCamera or SliceAtFocalPoint): "
           "casts nothing";
    return;
  }
  // The displayed slice (vtkImageSliceMapper::GetIndexBounds with the slice number): the
  // image extent, cropped, one index along the orientation axis, grown by half a pixel in
  // the slice plane when Border is on; corners through the image's index-to-physical map.
  const int orientation = mapper->GetOrientation() % 3;
  int extent[6];
  image->GetExtent(extent);
  if (mapper->GetCropping())
  {
    const int* crop = mapper->GetCroppingRegion();
    for (int c = 0; c < 3; ++c)
    {
      extent[2 * c] = std::max(extent[2 * c], crop[2 * c]);
      extent[2 * c + 1] = std::min(extent[2 * c + 1], crop[2 * c + 1]);
    }
  }
  const int number = mapper->GetSliceNumber();
  if (number < extent[2 * orientation] || number > extent[2 * orientation + 1] ||
    extent[0] > extent[1] || extent[2] > extent[3] || extent[4] > extent[5])
  {
    return; // nothing displayed
  }
  const double border = mapper->GetBorder() ? 0.5 : 0.0;
  const int u = (orientation + 1) % 3, v = (orientation + 2) % 3;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  for (int k = 0; k < 4; ++k)
  {
    double ijk[3], p[3];
    ijk[orientation] = number;
    ijk[u] = (k == 1 || k == 2) ? extent[2 * u + 1] + border : extent[2 * u] - border;
    ijk[v] = k >= 2 ? extent[2 * v + 1] + border : extent[2 * v] - border;
    image->TransformContinuousIndexToPhysicalPoint(ijk, p);
    points->InsertNextPoint(p);
  }
  vtkNew<vtkPolyData> quad;
  quad->SetPoints(points);
  vtkNew<vtkCellArray> polys;
  const vtkIdType ids[4] = { 0, 1, 2, 3 };
  polys->InsertNextCell(4, ids);
  quad->SetPolys(polys);
  AppendDrawnPolyData(quad, m, 0, style, drawn, casters, nullptr, outcome);

  // Its pixels are not cut out: say so when they can be transparent.
  vtkImageProperty* property = slice->GetProperty();
  vtkScalarsToColors* lut = property ? property->GetLookupTable() : nullptr;
  vtkDataArray* scalars = image->GetPointData()->GetScalars();
  const int comps = scalars ? scalars->GetNumberOfComponents() : 0;
  if ((lut && !lut->IsOpaque()) || (!lut && (comps == 2 || comps == 4)))
  {
    note = "image slice cast as a solid quad: its transparent pixels are not cut out";
  }
}
}
