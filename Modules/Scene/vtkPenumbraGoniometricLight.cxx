#include "vtkPenumbraGoniometricLight.h"

#include "vtkMath.h"
#include "vtkObjectFactory.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

vtkStandardNewMacro(vtkPenumbraGoniometricLight);

//------------------------------------------------------------------------------
vtkPenumbraGoniometricLight::vtkPenumbraGoniometricLight()
{
  this->SetPositional(true);
  this->SetConeAngle(180.0);
}

//------------------------------------------------------------------------------
int vtkPenumbraGoniometricLight::SetTable(const std::vector<double>& theta,
  const std::vector<double>& phi, const std::vector<double>& intensities)
{
  auto fail = [this](const std::string& why)
  {
    this->ErrorMessage = why;
    return 0;
  };
  auto increasing = [](const std::vector<double>& v, double last)
  {
    for (size_t i = 0; i < v.size(); ++i)
    {
      if (!std::isfinite(v[i]) || (i > 0 && !(v[i] > v[i - 1])) || v[i] > last)
      {
        return false;
      }
    }
    return !v.empty() && v[0] == 0.0;
  };
  if (!increasing(theta, 180.0))
  {
    return fail("theta must start at 0 and increase up to at most 180 degrees");
  }
  if (!increasing(phi, 360.0) || phi.back() >= 360.0)
  {
    return fail("phi must start at 0 and increase below 360 degrees");
  }
  if (intensities.size() != theta.size() * phi.size())
  {
    return fail("expected " + std::to_string(theta.size() * phi.size()) + " intensities (" +
      std::to_string(theta.size()) + " theta x " + std::to_string(phi.size()) + " phi), got " +
      std::to_string(intensities.size()));
  }
  double maximum = 0.0;
  for (double v : intensities)
  {
    if (!std::isfinite(v) || v < 0.0)
    {
      return fail("intensities must be finite and non-negative");
    }
    maximum = std::max(maximum, v);
  }
  if (!(maximum > 0.0))
  {
    return fail("at least one intensity must be positive");
  }
  this->Theta = theta;
  this->Phi = phi;
  this->Intensities = intensities;
  this->MaxIntensity = maximum;
  this->ErrorMessage.clear();
  this->Modified();
  return 1;
}

//------------------------------------------------------------------------------
int vtkPenumbraGoniometricLight::ReadFile(const char* fileName)
{
  std::ifstream file(fileName ? fileName : "");
  if (!file)
  {
    this->ErrorMessage = std::string("cannot open ") + (fileName ? fileName : "(null)");
    return 0;
  }
  // Strip comments, then read tokens.
  std::stringstream content;
  std::string line;
  while (std::getline(file, line))
  {
    const size_t hash = line.find('#');
    content << line.substr(0, hash) << "\n";
  }
  std::string magic;
  int version = 0;
  size_t n = 0, m = 0;
  std::vector<double> theta, phi, values;
  auto fail = [&](const std::string& why)
  {
    this->ErrorMessage = std::string(fileName) + ": " + why;
    return 0;
  };
  if (!(content >> magic >> version) || magic != "penumbra-goniometric" || version != 1)
  {
    return fail("not a 'penumbra-goniometric 1' file");
  }
  // "NAME count v_0 ... v_{count-1}"
  auto readAngles = [&content](const char* name, std::vector<double>& out)
  {
    std::string word;
    size_t count = 0;
    if (!(content >> word >> count) || word != name || count == 0 || count > 100000)
    {
      return false;
    }
    out.resize(count);
    for (double& v : out)
    {
      if (!(content >> v))
      {
        return false;
      }
    }
    return true;
  };
  if (!readAngles("theta", theta))
  {
    return fail("expected 'theta N' and N angles, N > 0");
  }
  if (!readAngles("phi", phi))
  {
    return fail("expected 'phi M' and M angles, M > 0");
  }
  n = theta.size();
  m = phi.size();
  values.resize(n * m);
  for (double& v : values)
  {
    if (!(content >> v))
    {
      return fail("expected " + std::to_string(n * m) + " intensities");
    }
  }
  std::string extra;
  if (content >> extra)
  {
    return fail("unexpected text after the intensities: " + extra);
  }
  if (!this->SetTable(theta, phi, values))
  {
    return fail(this->ErrorMessage);
  }
  return 1;
}

//------------------------------------------------------------------------------
double vtkPenumbraGoniometricLight::GetRelativeIntensity(const double direction[3])
{
  if (this->Theta.empty())
  {
    return 1.0;
  }
  double d[3] = { direction[0], direction[1], direction[2] };
  if (!(vtkMath::Normalize(d) > 0.0))
  {
    return 0.0;
  }
  double position[3], focal[3], axis[3];
  this->GetTransformedPosition(position);
  this->GetTransformedFocalPoint(focal);
  for (int c = 0; c < 3; ++c)
  {
    axis[c] = focal[c] - position[c];
  }
  if (!(vtkMath::Normalize(axis) > 0.0))
  {
    return 0.0;
  }
  double u[3] = { this->Up[0], this->Up[1], this->Up[2] };
  double along = vtkMath::Dot(u, axis);
  for (int c = 0; c < 3; ++c)
  {
    u[c] -= along * axis[c];
  }
  if (!(vtkMath::Normalize(u) > 1e-9))
  {
    u[0] = 1.0;
    u[1] = u[2] = 0.0;
    along = vtkMath::Dot(u, axis);
    for (int c = 0; c < 3; ++c)
    {
      u[c] -= along * axis[c];
    }
    vtkMath::Normalize(u);
  }
  double v[3];
  vtkMath::Cross(axis, u, v);
  const double theta = vtkMath::DegreesFromRadians(
    std::atan2(std::hypot(vtkMath::Dot(d, u), vtkMath::Dot(d, v)), vtkMath::Dot(d, axis)));
  double phi = vtkMath::DegreesFromRadians(std::atan2(vtkMath::Dot(d, v), vtkMath::Dot(d, u)));
  phi = phi < 0.0 ? phi + 360.0 : phi;

  // Bracket theta (nothing beyond the last row) and phi (wrapping to 360 = phi_0).
  const std::vector<double>& T = this->Theta;
  const std::vector<double>& P = this->Phi;
  if (theta > T.back())
  {
    return 0.0;
  }
  size_t i = static_cast<size_t>(std::upper_bound(T.begin(), T.end(), theta) - T.begin());
  i = std::min(std::max<size_t>(i, 1), T.size()) - 1;
  const size_t i1 = std::min(i + 1, T.size() - 1);
  const double ft = i1 > i ? (theta - T[i]) / (T[i1] - T[i]) : 0.0;
  size_t j = static_cast<size_t>(std::upper_bound(P.begin(), P.end(), phi) - P.begin());
  j = std::max<size_t>(j, 1) - 1;
  const size_t j1 = (j + 1) % P.size();
  const double phiNext = j + 1 < P.size() ? P[j + 1] : 360.0;
  const double fp = P.size() > 1 ? (phi - P[j]) / (phiNext - P[j]) : 0.0;
  auto at = [&](size_t a, size_t b) { return this->Intensities[a * P.size() + b]; };
  const double value = (1.0 - ft) * ((1.0 - fp) * at(i, j) + fp * at(i, j1)) +
    ft * ((1.0 - fp) * at(i1, j) + fp * at(i1, j1));
  return std::min(1.0, std::max(0.0, value / this->MaxIntensity));
}

//------------------------------------------------------------------------------
void vtkPenumbraGoniometricLight::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Up: " << this->Up[0] << " " << this->Up[1] << " " << this->Up[2] << "\n";
  os << indent << "Theta samples: " << this->Theta.size() << "\n";
  os << indent << "Phi samples: " << this->Phi.size() << "\n";
  os << indent << "MaxIntensity: " << this->MaxIntensity << "\n";
}
