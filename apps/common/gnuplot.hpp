#pragma once
// Small helpers of the command line (apps/cli) and the demos (demos/) for running gnuplot: the
// figures are drawn by gnuplot from the CSV files; nothing here is part of the library.
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <sstream>
#include <string>

namespace stackbeam::gnuplot {

/// Single-quoted for /bin/sh.
inline std::string shell_quote(const std::string& s) {
    std::string q = "'";
    for (char ch : s) q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
    return q + "'";
}

inline bool gnuplot_on_path() { return std::system("command -v gnuplot >/dev/null 2>&1") == 0; }

/// "pngcairo" or "png", whichever this gnuplot has; nullopt if neither.
inline std::optional<std::string> png_terminal() {
    FILE* pipe = popen("gnuplot -e 'set terminal' 2>&1", "r");
    if (!pipe) return std::nullopt;
    std::string text;
    char buf[512];
    while (std::fgets(buf, sizeof buf, pipe)) text += buf;
    pclose(pipe);
    auto has = [&](const std::string& name) {
        std::istringstream lines(text);
        std::string line;
        while (std::getline(lines, line)) {
            std::istringstream words(line);
            std::string first;
            if (words >> first && first == name) return true;
        }
        return false;
    };
    if (has("pngcairo")) return std::string("pngcairo");
    if (has("png")) return std::string("png");
    return std::nullopt;
}

}  // namespace stackbeam::gnuplot
