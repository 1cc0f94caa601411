"""Runs one Kratos case written by sheet.py and prints one JSON line: centre displacement,
Newton iterations per step, setup and solve seconds. Needs the Kratos venv (README.md).

usage: run_kratos.py STEM   (STEM_parameters.json, STEM_materials.json, STEM.mdpa)
"""

import json
import sys
import time

import KratosMultiphysics as KM
from KratosMultiphysics.StructuralMechanicsApplication.structural_mechanics_analysis import (
    StructuralMechanicsAnalysis,
)


class Timed(StructuralMechanicsAnalysis):
    """The standard analysis, recording each step's Newton iterations."""

    def __init__(self, model, parameters):
        super().__init__(model, parameters)
        self.iterations = []

    def FinalizeSolutionStep(self):
        super().FinalizeSolutionStep()
        info = self._GetSolver().GetComputingModelPart().ProcessInfo
        self.iterations.append(info[KM.NL_ITERATION_NUMBER])


def main(stem):
    KM.Logger.GetDefaultOutput().SetSeverity(KM.Logger.Severity.WARNING)
    with open(stem + "_parameters.json") as f:
        parameters = KM.Parameters(f.read())
    model = KM.Model()
    t0 = time.perf_counter()
    analysis = Timed(model, parameters)
    analysis.Initialize()
    t1 = time.perf_counter()
    step_s = []
    while analysis.KeepAdvancingSolutionLoop():
        ts = time.perf_counter()
        analysis.time = analysis._GetSolver().AdvanceInTime(analysis.time)
        analysis.InitializeSolutionStep()
        analysis._GetSolver().Predict()
        converged = analysis._GetSolver().SolveSolutionStep()
        if not converged:
            raise SystemExit(f"kratos: step at t = {analysis.time} did not converge")
        analysis.FinalizeSolutionStep()
        analysis.OutputSolutionStep()
        step_s.append(time.perf_counter() - ts)
        # Progress on stderr: a step's seconds and iterations (long runs can be judged early).
        print(f"kratos step {len(step_s)}: {analysis.iterations[-1]} iterations, {step_s[-1]:.2f} s",
              file=sys.stderr, flush=True)
    t2 = time.perf_counter()
    part = model["Structure.centre"]
    node = next(iter(part.Nodes))
    u = node.GetSolutionStepValue(KM.DISPLACEMENT)
    analysis.Finalize()
    print(json.dumps({"solver": "kratos", "centre": [u[0], u[1], u[2]],
                      "iterations": analysis.iterations, "step_s": step_s, "setup_s": t1 - t0,
                      "solve_s": t2 - t1}))


if __name__ == "__main__":
    main(sys.argv[1])
