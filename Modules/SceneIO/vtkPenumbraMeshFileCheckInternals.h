/**
 * @file   vtkPenumbraMeshFileCheckInternals.h
 * @brief  What the format checks of vtkPenumbraMeshFileCheck share: the problem they throw and
 *         the helpers more than one format needs. One file per format family:
 *         vtkPenumbraMeshFilePly.cxx, vtkPenumbraMeshFileObj.cxx and
 *         vtkPenumbraMeshFileLegacy.cxx; the class and the connectivity checks in
 *         vtkPenumbraMeshFileCheck.cxx. Private to the module.
 */

#ifndef vtkPenumbraMeshFileCheckInternals_h
#define vtkPenumbraMeshFileCheckInternals_h

#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace penumbra_mesh_check
{
// The first problem found; the message is the sentence the user reads.
struct FileProblem : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

[[noreturn]] inline void Fail(const std::string& what)
{
  throw FileProblem(what);
}

// Element counts beyond this do not fit the int vtkPLY stores them in.
constexpr long long PlyMaxCount = std::numeric_limits<int>::max();

// Defined with the PLY check (vtkPenumbraMeshFilePly.cxx), used by the others too.
std::vector<std::string> Words(const std::string& line);
double DecodeBinary(const unsigned char* b, int size, bool isSigned, bool isFloat, bool bigEndian);

// The format checks: each throws a FileProblem at the first problem it finds.
void CheckPly(const std::string& path);
void CheckObj(const std::string& path);
void CheckLegacy(const std::string& path);
}

#endif
// VTK-HeaderTest-Exclude: vtkPenumbraMeshFileCheckInternals.h
