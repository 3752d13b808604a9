/**
 * @file    vtkPenumbraSourcesPrivate.h
 * @brief   Internal helpers shared by the Penumbra::Sources classes (not installed, not wrapped).
 *
 * MeshBuilder accumulates triangles with their own point normals and a "PartId" per cell.
 * Geometry is given in local coordinates and translated by an offset only when a point is
 * stored, so that normals and sizes are computed without cancellation even when the offset
 * is a georeferenced coordinate of order 1e6..1e7 m.
 */

#ifndef vtkPenumbraSourcesPrivate_h
#define vtkPenumbraSourcesPrivate_h

#include "vtkCommand.h"
#include "vtkNew.h"
#include "vtkType.h"

#include <glm/vec3.hpp> // glm::dvec3: the double-precision vector of every Penumbra module

#include <array>
#include <cstdint>
#include <random>
#include <string>

class vtkAlgorithm;
class vtkCellArray;
class vtkFloatArray;
class vtkIntArray;
class vtkPoints;
class vtkPolyData;

namespace penumbra_sources
{
using Vec3 = glm::dvec3;

/**
 * Uniform double in [0, 1) built from two 32-bit draws (53 random bits). std's
 * distributions are implementation-defined, so they would make "same seed, same scene"
 * depend on the standard library; this mapping does not.
 */
double UniformUnit(std::mt19937& rng);

bool IsFinite(double v);
bool AllFinite(const double* v, int n);

class MeshBuilder
{
public:
  explicit MeshBuilder(const double offset[3] = nullptr);
  ~MeshBuilder();
  MeshBuilder(const MeshBuilder&) = delete;
  MeshBuilder& operator=(const MeshBuilder&) = delete;

  /**
   * Convex planar polygon (3 or 4 corners, any winding) with its own points. The winding is
   * fixed up so the geometric normal agrees with `facing`, and the stored point normal is
   * the geometric one, so shading and back-face culling always agree.
   */
  void AddPolygon(const Vec3* corners, int count, const Vec3& facing, int partId);

  /**
   * Planar parallelogram origin + s*u + t*v, s,t in [0,1], split into nu x nv quads (two
   * triangles each) sharing points; normal is +-(u x v), chosen to agree with `facing`.
   */
  void AddGrid(const Vec3& origin, const Vec3& u, const Vec3& v, int nu, int nv, const Vec3& facing,
    int partId);

  /**
   * Closed axis-aligned box [lo, hi]: six faces with outward normals.
   */
  void AddBox(const Vec3& lo, const Vec3& hi, int partId);

  /**
   * Vertical open cylinder wall around (cx, cy), radius r, z in [z0, z1], smooth normals
   * pointing away from the axis, or toward it if `towardAxis`.
   */
  void AddCylinderWall(double cx, double cy, double r, double z0, double z1, int segments,
    bool towardAxis, int partId);

  /**
   * Horizontal flat annulus r0 < r1 at height z, normal +z if `up`, else -z.
   */
  void AddAnnulus(
    double cx, double cy, double r0, double r1, double z, int segments, bool up, int partId);

  vtkIdType GetNumberOfCells() const;

  /** Move everything accumulated so far into `output` (replacing its contents). */
  void Finish(vtkPolyData* output);

private:
  vtkIdType InsertPoint(const Vec3& p, const Vec3& n);
  void InsertTriangle(vtkIdType a, vtkIdType b, vtkIdType c, int partId);

  Vec3 Offset;
  vtkNew<vtkPoints> Points;
  vtkNew<vtkFloatArray> Normals;
  vtkNew<vtkCellArray> Polys;
  vtkNew<vtkIntArray> PartIds;
};

/**
 * Collects ErrorEvent/WarningEvent messages of internal readers and filters so a source can
 * re-report them as its own: otherwise they would reach the output window under the name of
 * an object the caller never saw and cannot observe.
 */
class MessageCollector : public vtkCommand
{
public:
  static MessageCollector* New() { return new MessageCollector; }
  void Execute(vtkObject* caller, unsigned long event, void* callData) override;

  /** Observe the algorithm and its executive (which reports "returned failure"). */
  void Watch(vtkAlgorithm* algorithm);

  bool HasError() const { return !this->Errors.empty() || !this->ExecutiveErrors.empty(); }
  const std::string& GetErrors() const
  {
    return this->Errors.empty() ? this->ExecutiveErrors : this->Errors;
  }
  const std::string& GetWarnings() const { return this->Warnings; }

private:
  MessageCollector() = default;
  std::string Errors;
  std::string ExecutiveErrors;
  std::string Warnings;
};
}

#endif
// VTK-HeaderTest-Exclude: vtkPenumbraSourcesPrivate.h
