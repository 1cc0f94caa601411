"""Drive an FMI 2.0 Co-Simulation FMU with libcosim (via libcosimpy 0.0.6).

Usage::

    from cosim_runner import run_with_libcosim
    res = run_with_libcosim("target/membrane.fmu", {0: [1.0] * 10}, 1e-3, 10,
                            real_outputs=[5, 6], integer_outputs=[7])
    res["time"]          # [t1, ..., tN] in seconds, after each step
    res["real"][5]       # value of real vr 5 after each step
    res["integer"][7]    # value of integer vr 7 after each step

Input semantics: ``real_inputs[vr][k]`` is the value the FMU sees during step
``k`` (the step from ``t_k`` to ``t_k + step_size``).  Value ``[0]`` is also set
as the initial value (applied by libcosim in initialization mode), the rest are
applied through an override manipulator, which calls ``fmi2SetReal`` just
before each ``fmi2DoStep``.

What libcosim does to the FMU (observed with a tracing probe FMU):
  * unpacks into ``$TMPDIR/libcosim_<uuid>/<guid without braces>/`` and passes
    ``file:///.../resources`` (percent-encoded UTF-8, no trailing slash);
  * fmi2Instantiate(visible=0, loggingOn=1), then fmi2SetReal for parameters
    (Instantiated state), fmi2SetupExperiment(start=0, stopTimeDefined=0),
    fmi2EnterInitializationMode, fmi2SetReal for initial values,
    fmi2ExitInitializationMode, then fmi2DoStep(noSetFMUStatePriorToCurrentPoint=1);
  * the step size h is (t_{k+1} - t_k) with times in integer nanoseconds, so h
    jitters in the last bits (0.1 -> 0.099999999999999978);
  * Instantiate/Terminate/FreeInstance run on the calling thread; everything
    else runs on a libcosim worker thread;
  * the last-value observer used here makes libcosim call fmi2GetReal /
    fmi2GetInteger on *every* variable of that type (inputs, parameters,
    locals too), in initialization mode and after every step;
  * fmi2DoStep returning Discard or Error makes the step fail (execution goes to
    ERROR state); Warning is logged and the run continues.
"""

from __future__ import annotations

from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimManipulator import CosimManipulator
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimSlave import CosimLocalSlave
from libcosimpy._internal import get_last_error_message

NANOS = 1_000_000_000


def run_with_libcosim(
    fmu_path: str,
    real_inputs: dict[int, list[float]],
    step_size: float,
    n_steps: int,
    real_outputs: list[int],
    integer_outputs: list[int],
    log_level: CosimLogLevel = CosimLogLevel.WARNING,
    instance_name: str = "fmu",
) -> dict:
    """Run ``fmu_path`` for ``n_steps`` steps of ``step_size`` seconds.

    Returns ``{"time": [...], "real": {vr: [...]}, "integer": {vr: [...]}}``,
    one entry per step, read after the step.  Raises ``RuntimeError`` (with
    libcosim's last error message) if loading or a step fails.
    """
    for vr, values in real_inputs.items():
        if len(values) < n_steps:
            raise ValueError(f"real_inputs[{vr}] has {len(values)} values, need {n_steps}")
    # libcosim's default console level is 'debug', which is very chatty.
    log_output_level(log_level)

    step_ns = round(step_size * NANOS)
    if step_ns <= 0:
        raise ValueError("step_size must be at least 1 ns")
    execution = CosimExecution.from_step_size(step_ns)

    slave = CosimLocalSlave(fmu_path=str(fmu_path), instance_name=instance_name)
    # A NULL slave (bad zip, bad XML, a missing fmi2 symbol, ...) would make
    # add_local_slave segfault, so check first.
    if not slave.ptr():
        raise RuntimeError(f"libcosim could not load {fmu_path}: {get_last_error_message()}")
    index = execution.add_local_slave(slave)
    if index < 0:
        raise RuntimeError(f"add_local_slave failed: {get_last_error_message()}")

    observer = CosimObserver.create_last_value()
    manipulator = CosimManipulator.create_override()
    if not (execution.add_observer(observer) and execution.add_manipulator(manipulator)):
        raise RuntimeError(get_last_error_message())

    for vr, values in real_inputs.items():
        if not execution.real_initial_value(index, vr, float(values[0])):
            raise RuntimeError(f"real_initial_value(vr={vr}) failed: {get_last_error_message()}")

    result: dict = {
        "time": [],
        "real": {vr: [] for vr in real_outputs},
        "integer": {vr: [] for vr in integer_outputs},
    }
    input_vrs = list(real_inputs)
    for k in range(n_steps):
        if input_vrs:
            values = [float(real_inputs[vr][k]) for vr in input_vrs]
            if not manipulator.slave_real_values(index, input_vrs, values):
                raise RuntimeError(f"setting inputs failed: {get_last_error_message()}")
        if not execution.step(1):
            raise RuntimeError(f"step {k} failed: {get_last_error_message()}")
        result["time"].append(execution.status().current_time / NANOS)
        if real_outputs:
            for vr, v in zip(real_outputs, observer.last_real_values(index, real_outputs)):
                result["real"][vr].append(v)
        if integer_outputs:
            for vr, v in zip(integer_outputs, observer.last_integer_values(index, integer_outputs)):
                result["integer"][vr].append(v)

    # Terminate + FreeInstance happen when the execution is destroyed.
    del execution
    return result


def run_ssp_with_libcosim(ssp_path: str, n_steps: int, outputs: dict[str, list[str]],
                          log_level: CosimLogLevel = CosimLogLevel.WARNING) -> dict:
    """Run an ``.ssp`` archive as it is (``CosimExecution.from_ssp_file``: its components,
    connections, parameter values and the fixed step of its libcosim annotation) for
    ``n_steps`` steps. ``outputs``: ``{component: [variable names]}`` to read after the last
    step. Returns ``{"time": end time in s, component: {name: value}}``."""
    from libcosimpy.CosimExecution import CosimExecution

    log_output_level(log_level)
    execution = CosimExecution.from_ssp_file(str(ssp_path))
    observer = CosimObserver.create_last_value()
    if not execution.add_observer(observer):
        raise RuntimeError(get_last_error_message())
    index = {i.name.decode(): i.index for i in execution.slave_infos()}
    refs = {c: {v.name.decode(): v.reference for v in execution.slave_variables(index[c])} for c in outputs}
    if not execution.step(n_steps):
        raise RuntimeError(f"the SSP run failed: {get_last_error_message()}")
    result: dict = {"time": execution.status().current_time / NANOS}
    for c, names in outputs.items():
        values = observer.last_real_values(index[c], [refs[c][n] for n in names])
        result[c] = dict(zip(names, values))
    del execution
    return result
