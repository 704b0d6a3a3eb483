#pragma once
/// @file csv.hpp
/// CSV output of step records, to a stream the caller provides.
#include <ostream>
#include <vector>

#include "stackbeam/time/cvode_stepper.hpp"
#include "stackbeam/time/simulation.hpp"

namespace stackbeam {

/// Writes a header line (step_record_columns()) and one line per record, full precision.
void write_csv(std::ostream& out, const std::vector<StepRecord>& records);
void write_csv_header(std::ostream& out);
void write_csv_row(std::ostream& out, const StepRecord& record);

/// The event log of mode cvode: header
/// t,interface,x,pair,from,to,cause,w,w_dot  (SI units: s, -, m, -, -, -, -, m, m/s)
/// and one line per transition.
void write_events_csv(std::ostream& out, const std::vector<ContactEvent>& events);

}  // namespace stackbeam
