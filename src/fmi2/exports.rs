//! The exported FMI 2.0 functions: 25 common, 9 Co-Simulation, and the 10 Model Exchange ones
//! as error stubs (fmpy and FMIL bind every symbol when they load the library), made by the
//! shared glue's `fmi_glue::export_fmi2!` over the instance's [`Core`](fmi_glue::core::Core)
//! (`core.rs`), as for the jack and the inflation unit. Every `unsafe` block is the glue's (its
//! C layer, `fmu/glue/src/fmi2.rs`, each with its soundness comment): it checks the pointers and
//! the phase and catches panics, the instance does the work.
//!
//! The functions keep the names they had here, `fmi2_<name>` (the exported C name is the
//! standard's), so that Rust tests and benchmarks call them through the rlib exactly as an
//! importer does. Every one relies on the caller contract of FMI 2.0 §2.1: `c` is NULL or an
//! instance returned by `fmi2Instantiate` and not yet freed, calls on one instance are not
//! concurrent, arrays hold the announced number of elements, strings are NUL-terminated.

use super::instance::Instance;

fmi_glue::export_fmi2!(Instance);

pub use fmi2_exports::{
    cancel_step as fmi2_cancel_step, completed_integrator_step as fmi2_completed_integrator_step,
    deserialize as fmi2_de_serialize_fmu_state, do_step as fmi2_do_step,
    enter_continuous_time_mode as fmi2_enter_continuous_time_mode,
    enter_event_mode as fmi2_enter_event_mode,
    enter_initialization_mode as fmi2_enter_initialization_mode,
    exit_initialization_mode as fmi2_exit_initialization_mode,
    free_fmu_state as fmi2_free_fmu_state, free_instance as fmi2_free_instance,
    get_boolean as fmi2_get_boolean, get_boolean_status as fmi2_get_boolean_status,
    get_continuous_states as fmi2_get_continuous_states, get_derivatives as fmi2_get_derivatives,
    get_directional_derivative as fmi2_get_directional_derivative,
    get_event_indicators as fmi2_get_event_indicators, get_fmu_state as fmi2_get_fmu_state,
    get_integer as fmi2_get_integer, get_integer_status as fmi2_get_integer_status,
    get_nominals as fmi2_get_nominals_of_continuous_states,
    get_output_derivatives as fmi2_get_real_output_derivatives, get_real as fmi2_get_real,
    get_real_status as fmi2_get_real_status, get_status as fmi2_get_status,
    get_string as fmi2_get_string, get_string_status as fmi2_get_string_status,
    get_types_platform as fmi2_get_types_platform, get_version as fmi2_get_version,
    instantiate as fmi2_instantiate, new_discrete_states as fmi2_new_discrete_states,
    reset as fmi2_reset, serialize as fmi2_serialize_fmu_state,
    serialized_size as fmi2_serialized_fmu_state_size, set_boolean as fmi2_set_boolean,
    set_continuous_states as fmi2_set_continuous_states,
    set_debug_logging as fmi2_set_debug_logging, set_fmu_state as fmi2_set_fmu_state,
    set_input_derivatives as fmi2_set_real_input_derivatives, set_integer as fmi2_set_integer,
    set_real as fmi2_set_real, set_string as fmi2_set_string, set_time as fmi2_set_time,
    setup_experiment as fmi2_setup_experiment, terminate as fmi2_terminate,
};
