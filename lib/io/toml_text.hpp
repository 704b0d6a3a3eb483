#pragma once
// Checks of a TOML text before toml11 parses it (internal to the library): what the
// parser does not survive. Used by the scenario reader and the sweep spec reader.
#include <string>

namespace stackbeam::detail {

/// Throws InputError(source_name, "TOML syntax error: ...") for arrays or tables nested
/// deeper than 32 levels (the parser recurses: thousands of '[' overflow the stack) and
/// for bytes that are not UTF-8 (TOML requires it; toml11's error report of bad UTF-8 in
/// a literal string reads out of bounds, found by fuzz_scenario and fuzz_sweep_spec):
/// the message names the byte, its line and column.
void check_toml_text(const std::string& text, const std::string& source_name);

}  // namespace stackbeam::detail

namespace stackbeam::detail {

/// The largest input text file read (a scenario, a sweep spec): 16 MiB. A scenario is a few
/// kB; the cap keeps a wrong path (a log, an image) from filling memory.
constexpr long long max_input_file_bytes = 16LL * 1024 * 1024;

/// Reads the regular file `path` whole. Refuses, before reading, what is not a regular file
/// (a directory, a device such as /dev/zero, a FIFO: opened with O_NONBLOCK, so a FIFO never
/// blocks) and a file of more than `max_bytes`. Throws InputError(field, "<what> 'path' ...: why",
/// location) naming the system's reason (strerror) when it cannot be opened or read.
std::string read_input_file(const std::string& path, const std::string& what, const std::string& field,
                            const std::string& location = "", long long max_bytes = max_input_file_bytes);

}  // namespace stackbeam::detail
