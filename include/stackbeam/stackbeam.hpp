#pragma once
/// @file stackbeam.hpp
/// The whole public API in one include. The headers follow the include order:
///   contact/  the ground numerics layer (Eigen only): the pair laws, the per-step frictional
///             contact problem (dense or sparse operator) and its solvers
///   model/    the spring as the user describes it (leaves, interfaces, clamps, body),
///             the paper's example, the loadings
///   fe/       the finite-element system built from it (stiffness, contact rows, mass)
///             and its natural frequencies
///   time/     the time-stepping modes (closed-form, cvode, newmark) and simulate()
///   io/       scenario files (TOML) and CSV output
///   post/     hysteresis-loop figures of a run, the Fancher model fitted to a loop,
///             fatigue of the leaves from stress histories (rainflow, S-N, Miner)
///   study/    sweeps: a base scenario at many points, on threads; the results directory
#include "stackbeam/conventions.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/contact/pair.hpp"
#include "stackbeam/contact/contact.hpp"
#include "stackbeam/contact/step.hpp"
#include "stackbeam/model/model.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/model/loading.hpp"
#include "stackbeam/fe/system.hpp"
#include "stackbeam/fe/modal.hpp"
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/time/option_table.hpp"
#include "stackbeam/time/run_report.hpp"
#include "stackbeam/time/stepper.hpp"
#include "stackbeam/time/closed_form_stepper.hpp"
#include "stackbeam/time/cvode_stepper.hpp"
#include "stackbeam/time/newmark_stepper.hpp"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/io/csv.hpp"
#include "stackbeam/post/fancher.hpp"
#include "stackbeam/post/fatigue.hpp"
#include "stackbeam/post/fibre.hpp"
#include "stackbeam/post/hysteresis.hpp"
#include "stackbeam/post/stresses.hpp"
#include "stackbeam/study/sweep.hpp"
#include "stackbeam/study/sweep_output.hpp"
