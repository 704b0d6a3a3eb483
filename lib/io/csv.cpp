#include "stackbeam/io/csv.hpp"

#include <cstdio>

namespace stackbeam {

void write_csv_header(std::ostream& out) {
    const auto cols = step_record_columns();
    for (std::size_t i = 0; i < cols.size(); ++i) out << (i ? "," : "") << cols[i];
    out << '\n';
}

void write_csv_row(std::ostream& out, const StepRecord& record) {
    const auto vals = step_record_values(record);
    char buf[40];
    for (std::size_t i = 0; i < vals.size(); ++i) {
        std::snprintf(buf, sizeof buf, "%.12g", vals[i]);
        out << (i ? "," : "") << buf;
    }
    out << '\n';
}

void write_events_csv(std::ostream& out, const std::vector<ContactEvent>& events) {
    out << "t,interface,x,pair,from,to,cause,w,w_dot\n";
    char buf[200];
    for (const auto& e : events) {
        std::snprintf(buf, sizeof buf, "%.15g,%d,%.12g,%d,%s,%s,%s,%.12g,%.12g", e.t_s, e.interface_index, e.x_m, e.pair,
                      e.from.c_str(), e.to.c_str(), e.cause.c_str(), e.w_m, e.w_dot_m_per_s);
        out << buf << '\n';
    }
}

void write_csv(std::ostream& out, const std::vector<StepRecord>& records) {
    write_csv_header(out);
    for (const auto& r : records) write_csv_row(out, r);
}

}  // namespace stackbeam
