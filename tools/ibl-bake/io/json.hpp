#pragma once
// tools/ibl-bake/io/json.hpp — a small streaming JSON writer (RFC 8259) for sh.json and
// report.json; no dependency.
//
//   json_writer j;
//   j.begin_object();
//   j.key("order").value(3);
//   j.key("coeffs").begin_array(); for (float c : cs) j.value(c); j.end_array();
//   j.end_object();
//   std::string text = j.str();
//
// Numbers: integers exactly; double with the shortest decimal that reads back to the same double
// and float with the shortest that reads back to the same float (std::to_chars: round-trip,
// locale-independent; e.g. 0.1f -> 0.1, 1e-30 -> 1e-30). Non-finite numbers (NaN, +-inf) have no
// JSON representation and are written as null: a reader sees "no value" instead of a parse error,
// and report.json states which metric could not be computed.
// Strings: '"', '\\' and control characters are escaped (\b \f \n \r \t, others \u00XX); bytes
// that are not valid UTF-8 (e.g. a file name in another encoding) are replaced by U+FFFD so that
// the output is always valid UTF-8 JSON.
// Structure: misuse (a value where a key is expected, unbalanced end_*) throws std::logic_error;
// str() requires a complete document.

#include <charconv>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace ibl_bake {

class json_writer {
public:
    /// indent = 0 writes one line; otherwise newlines and `indent` spaces per level.
    explicit json_writer(int indent = 2) : indent_(indent) {}

    json_writer& begin_object() { return open('{', true); }
    json_writer& end_object() { return close('}', true); }
    json_writer& begin_array() { return open('[', false); }
    json_writer& end_array() { return close(']', false); }

    json_writer& key(std::string_view k) {
        if (stack_.empty() || !stack_.back().object || stack_.back().expect_value)
            throw std::logic_error("json_writer: key outside an object or twice");
        separator();
        write_string(k);
        out_ += indent_ ? ": " : ":";
        stack_.back().expect_value = true;
        return *this;
    }

    json_writer& value(std::string_view s) {
        before_value();
        write_string(s);
        return *this;
    }
    json_writer& value(const char* s) { return value(std::string_view(s)); }
    json_writer& value(bool b) {
        before_value();
        out_ += b ? "true" : "false";
        return *this;
    }
    json_writer& null() {
        before_value();
        out_ += "null";
        return *this;
    }
    template <class I>
        requires(std::is_integral_v<I> && !std::is_same_v<I, bool>)
    json_writer& value(I i) {
        before_value();
        char buf[32];
        const auto r = std::to_chars(buf, buf + sizeof buf, i);
        out_.append(buf, r.ptr);
        return *this;
    }
    json_writer& value(double d) { return floating(d); }
    json_writer& value(float f) { return floating(f); }

    /// The document; throws std::logic_error if it is not complete.
    const std::string& str() const {
        if (!stack_.empty() || !done_) throw std::logic_error("json_writer: incomplete document");
        return out_;
    }

private:
    struct level {
        bool object;
        bool first = true;
        bool expect_value = false;
    };

    template <class F> json_writer& floating(F x) {
        if (!std::isfinite(x)) return null();
        before_value();
        char buf[64];
        const auto r = std::to_chars(buf, buf + sizeof buf, x); // shortest round-trip form
        out_.append(buf, r.ptr);
        return *this;
    }

    json_writer& open(char c, bool object) {
        before_value();
        out_ += c;
        stack_.push_back({object});
        return *this;
    }
    json_writer& close(char c, bool object) {
        if (stack_.empty() || stack_.back().object != object || stack_.back().expect_value)
            throw std::logic_error("json_writer: unbalanced end");
        const bool empty = stack_.back().first;
        stack_.pop_back();
        if (!empty) newline();
        out_ += c;
        if (stack_.empty()) done_ = true;
        return *this;
    }
    void before_value() {
        if (stack_.empty()) {
            if (done_) throw std::logic_error("json_writer: a second top-level value");
            done_ = true; // a scalar document (re-armed by open for containers)
            return;
        }
        level& l = stack_.back();
        if (l.object) {
            if (!l.expect_value) throw std::logic_error("json_writer: value without a key in an object");
            l.expect_value = false;
            l.first = false;
        } else {
            separator();
        }
    }
    void separator() {
        level& l = stack_.back();
        if (!l.first) out_ += ',';
        if (!l.object) l.first = false;
        newline();
    }
    void newline() {
        if (!indent_) return;
        out_ += '\n';
        out_.append(std::size_t(indent_) * stack_.size(), ' ');
    }

    void write_string(std::string_view s) {
        out_ += '"';
        std::size_t i = 0;
        while (i < s.size()) {
            const unsigned char c = static_cast<unsigned char>(s[i]);
            if (c < 0x80) {
                switch (c) {
                case '"': out_ += "\\\""; break;
                case '\\': out_ += "\\\\"; break;
                case '\b': out_ += "\\b"; break;
                case '\f': out_ += "\\f"; break;
                case '\n': out_ += "\\n"; break;
                case '\r': out_ += "\\r"; break;
                case '\t': out_ += "\\t"; break;
                default:
                    if (c < 0x20) {
                        static constexpr char hex[] = "0123456789abcdef";
                        out_ += "\\u00";
                        out_ += hex[c >> 4];
                        out_ += hex[c & 15];
                    } else {
                        out_ += static_cast<char>(c);
                    }
                }
                ++i;
                continue;
            }
            const std::size_t n = utf8_sequence_length(s, i);
            if (n == 0) {
                out_ += "\xEF\xBF\xBD"; // U+FFFD
                ++i;
            } else {
                out_.append(s.substr(i, n));
                i += n;
            }
        }
        out_ += '"';
    }

    /// Length of the valid UTF-8 sequence at s[i] (RFC 3629: no overlongs, no surrogates,
    /// at most U+10FFFF), or 0 if it is not valid.
    static std::size_t utf8_sequence_length(std::string_view s, std::size_t i) {
        const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
        const unsigned char c = byte(i);
        std::size_t n;
        unsigned char lo = 0x80, hi = 0xBF; // allowed range of the second byte
        if (c >= 0xC2 && c <= 0xDF) n = 2;
        else if (c >= 0xE0 && c <= 0xEF) {
            n = 3;
            if (c == 0xE0) lo = 0xA0;
            if (c == 0xED) hi = 0x9F;
        } else if (c >= 0xF0 && c <= 0xF4) {
            n = 4;
            if (c == 0xF0) lo = 0x90;
            if (c == 0xF4) hi = 0x8F;
        } else
            return 0;
        if (i + n > s.size()) return 0;
        if (byte(i + 1) < lo || byte(i + 1) > hi) return 0;
        for (std::size_t k = 2; k < n; ++k)
            if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
        return n;
    }

    std::string out_;
    std::vector<level> stack_;
    int indent_;
    bool done_ = false;
};

} // namespace ibl_bake
