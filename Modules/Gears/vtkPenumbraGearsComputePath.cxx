// GEARS' masks on the compute path (vtkPenumbraGearsMaskCS.glsl): one side's masks from
// the shader, the samples it leaves to the CPU.
#include "vtkPenumbraGearsShadowsInternals.h"

//------------------------------------------------------------------------------
// Step 4 on the compute path: the shader's masks for this side, the samples it flagged left
// to the CPU (Scratch.OnCPU). False, with the path dropped for the rest of the call, if the
// run failed.
bool vtkPenumbraGearsShadows::Internals::MasksOnComputePath(
  vtkPenumbraGearsShadows* self, CallState& call, const SideState& S)
{
  ScratchArrays& sc = this->Scratch;
  const LightSamples& ls = call.Light;
  const vtkIdType m = S.M;
  std::vector<std::uint32_t>& work = sc.Work;
  work.assign(2 * static_cast<size_t>(m), 0u);
  for (vtkIdType o = 0; o < m; ++o)
  {
    const std::uint32_t q = sc.SampleOrder[static_cast<size_t>(o)];
    work[2 * o] = static_cast<std::uint32_t>(sc.Ids[q]);
    work[2 * o + 1] = static_cast<std::uint32_t>(sc.SampleCell[q]);
  }
  penumbra_gears::ComputeLight cl;
  cl.K = ls.K;
  cl.Rows = ls.Rows;
  cl.Points = ls.Points.data();
  std::copy(ls.Centre, ls.Centre + 3, cl.Centre);
  std::copy(ls.U, ls.U + 3, cl.U);
  std::copy(ls.V, ls.V + 3, cl.V);
  std::copy(ls.N, ls.N + 3, cl.N);
  cl.Su0 = ls.Su0;
  cl.DSu = ls.DSu;
  cl.Sv0 = ls.Sv0;
  cl.DSv = ls.DSv;
  for (int j = 0; j < ls.Rows && j < 32; ++j)
  {
    cl.Emitting[j] = static_cast<std::uint32_t>(ls.Emitting[j]);
  }
  penumbra_gears::ComputeConstants cc;
  std::copy(call.Shift, call.Shift + 3, cc.Shift);
  cc.Epsilon = call.Epsilon;
  cc.TieFactor = call.TieFactor;
  cc.Diagonal = call.Diagonal;
  cc.RelativeTolerance = RelativePositionTolerance;
  penumbra_gears::ComputeSide cs;
  cs.Flip = S.Flip;
  cs.FarSlack = S.Tolerance;
  cs.ZNear = S.ZNear.data();
  cs.CellStart = sc.CellStart.data();
  cs.Cells = sc.CellStart.size() - 1;
  cs.CellList = sc.CellList.data();
  cs.ListSize = sc.CellList.size();
  cs.GlobalList = sc.GlobalList.data();
  cs.GlobalSize = sc.GlobalList.size();
  cs.Work = work.data();
  cs.WorkCount = static_cast<size_t>(m);
  std::string why;
  if (!this->Compute.Run(cl, cc, cs, sc.Results, call.Masks ? &sc.Rows : nullptr, why))
  {
    this->ReportPathProblem(self, why);
    call.UseGpu = false;
    return false;
  }
  self->LastPath = PATH_GPU;
  vtkIdType sideNecessary = 0, sideTests = 0;
  for (vtkIdType o = 0; o < m; ++o)
  {
    const std::uint32_t* res = &sc.Results[3 * static_cast<size_t>(o)];
    if (res[0] == penumbra_gears::Flagged)
    {
      sc.OnCPU.push_back(static_cast<std::uint32_t>(o));
      continue;
    }
    const vtkIdType s = sc.Ids[sc.SampleOrder[static_cast<size_t>(o)]];
    call.Vis[s] = static_cast<float>(res[0]) / static_cast<float>(ls.Count);
    sideNecessary += res[1];
    sideTests += res[2];
    if (call.Masks)
    {
      std::uint64_t rows[MaxK];
      for (int j = 0; j < ls.Rows; ++j)
      {
        rows[j] = sc.Rows[static_cast<size_t>(o) * ls.Rows + j];
      }
      call.WriteMask(s, rows);
    }
  }
  call.Necessary += sideNecessary;
  call.SegmentTests += sideTests;
  call.Flagged += static_cast<vtkIdType>(sc.OnCPU.size());
  return true;
}
