#pragma once
/// @file words.hpp
/// One word table per enum: the words a user writes for its values (scenario files, command-line
/// flags, the Python module), used to parse them, print them and write them back. Each enum's
/// table is a specialisation of enum_words<E>(), declared in the enum's header and defined once
/// next to its to_string (STACKBEAM_ENUM_WORDS); every reader, writer and front-end goes through it, so a word is
/// spelled in one place. Each parser keeps its own message (and names its field), built with
/// word_list().
#include <optional>
#include <string>
#include <vector>

#include "stackbeam/errors.hpp"

namespace stackbeam {

/// One value of an enum and its word.
template <class E>
struct EnumWord {
    E value;
    const char* word;
};

/// The word table of the enum E (in the order messages list them).
template <class E>
const std::vector<EnumWord<E>>& enum_words();

/// Defines the specialisation enum_words<E>() (in a .cpp, once), its rows {E::value, "word"} in the
/// order messages list them (the form of nlohmann::json's NLOHMANN_JSON_SERIALIZE_ENUM):
///     STACKBEAM_ENUM_WORDS(Mode, {Mode::closed_form, "closed-form"}, {Mode::cvode, "cvode"}, {Mode::newmark, "newmark"})
#define STACKBEAM_ENUM_WORDS(E, ...)                                 \
    template <>                                                      \
    const std::vector<EnumWord<E>>& enum_words<E>() {                \
        static const std::vector<EnumWord<E>> words = {__VA_ARGS__}; \
        return words;                                                \
    }

/// The word of `value` ("?" for a value without one).
template <class E>
const char* word_of(E value) {
    for (const auto& w : enum_words<E>())
        if (w.value == value) return w.word;
    return "?";
}

/// The value whose word is `text`, if any.
template <class E>
std::optional<E> find_word(const std::string& text) {
    for (const auto& w : enum_words<E>())
        if (text == w.word) return w.value;
    return std::nullopt;
}

/// The value whose word is `text`, else InputError naming `field`: "value '<text>' is not a <what>:
/// allowed <word_list<E>()>" (the one message of parse_mode, parse_leaf_inertia, parse_solver_kind,
/// parse_contact_path, parse_tau_rule and parse_paper_case).
template <class E>
E parse_word(const std::string& text, const std::string& field, const char* what);

/// The words for a message: each in `quote`, separated by `separator` and the last by
/// `last_separator` (nullptr: `separator`): word_list<Mode>() is "closed-form, cvode, newmark",
/// word_list<Symmetry>("'", ", ", " or ") is "'full' or 'half'", word_list<Mode>("", " | ") is
/// "closed-form | cvode | newmark".
template <class E>
std::string word_list(const char* quote = "", const char* separator = ", ", const char* last_separator = nullptr) {
    const auto& words = enum_words<E>();
    std::string out;
    for (std::size_t i = 0; i < words.size(); ++i) {
        if (i > 0) out += i + 1 == words.size() && last_separator ? last_separator : separator;
        out += std::string(quote) + words[i].word + quote;
    }
    return out;
}

template <class E>
E parse_word(const std::string& text, const std::string& field, const char* what) {
    if (const auto value = find_word<E>(text)) return *value;
    throw InputError(field, "value '" + text + "' is not a " + what + ": allowed " + word_list<E>());
}

}  // namespace stackbeam
