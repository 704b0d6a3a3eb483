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
