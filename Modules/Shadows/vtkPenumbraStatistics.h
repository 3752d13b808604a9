/**
 * @class   vtkPenumbraStatistics
 * @brief   A technique's counts and phase times of the last frame, as a name -> value table.
 *
 * Every technique describes its last frame in one of these
 * (vtkPenumbraShadowTechnique::GetStatistics(), vtkPenumbraShadowPass::GetLightStatistics()),
 * so that the benchmark, `penumbra-render --explain` and ParaView print any technique's
 * figures without knowing its class. Entries keep the order in which they were first set.
 *
 * Names are lower case words joined by underscores, ending in their unit where they have one:
 * `_ms` for wall-clock milliseconds, `_share` for a fraction in [0, 1]; plain counts have no
 * suffix ("traced_rays", "grid_ms", "uncertain_share").
 */

#ifndef vtkPenumbraStatistics_h
#define vtkPenumbraStatistics_h

#include "vtkObject.h"
#include "vtkPenumbraShadowsModule.h" // For export macro

#include <string> // For Format
#include <vector> // For the entries

class VTKPENUMBRASHADOWS_EXPORT vtkPenumbraStatistics : public vtkObject
{
public:
  static vtkPenumbraStatistics* New();
  vtkTypeMacro(vtkPenumbraStatistics, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Removes every entry.
   */
  void Clear();

  /**
   * Sets entry `name` to `value`; a new name is appended after the existing entries.
   */
  void Set(const char* name, double value);

  /**
   * Number of entries.
   */
  int GetNumberOfEntries();

  /**
   * Name and value of entry `index` in [0, GetNumberOfEntries()); "" and NaN out of range.
   */
  const char* GetName(int index);
  double GetValue(int index);

  /**
   * True when entry `name` is set.
   */
  bool Has(const char* name);

  /**
   * Value of entry `name`, NaN when it is not set.
   */
  double Get(const char* name);

  /**
   * The entries as "name value" pairs joined by `separator` (integers without a fraction,
   * other values with four significant digits).
   */
  std::string Format(const char* separator = ", ");

protected:
  vtkPenumbraStatistics() = default;
  ~vtkPenumbraStatistics() override = default;

private:
  struct Entry
  {
    std::string Name;
    double Value;
  };
  std::vector<Entry> Entries;
  Entry* Find(const char* name); // nullptr when `name` is not set

  vtkPenumbraStatistics(const vtkPenumbraStatistics&) = delete;
  void operator=(const vtkPenumbraStatistics&) = delete;
};

#endif
