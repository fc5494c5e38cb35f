// json_value.hpp — a small, strict JSON reader for ibl-bake --scene (RFC 8259: objects, arrays,
// strings with every escape including \uXXXX surrogate pairs, numbers, true/false/null), plus the
// four non-standard number spellings Google Benchmark writes for non-finite counters
// (NaN, -NaN, Infinity, -Infinity). Errors throw json_error with "line:column: what".
// Nesting is limited (json_max_depth) so hostile input cannot overflow the stack.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace ibl_examples {

struct json_error : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// A JSON value. Objects keep their members in file order as parallel key / value arrays
/// (duplicate keys: the last one wins on lookup, as most readers do).
struct json_value {
    enum class kind { null, boolean, number, string, array, object };

    kind type = kind::null;
    bool boolean = false;
    double number = 0.0;
    std::string string;
    std::vector<std::string> keys;     // object member names
    std::vector<json_value> values;    // object member values, or the array's elements

    [[nodiscard]] bool is_object() const { return type == kind::object; }
    [[nodiscard]] bool is_array() const { return type == kind::array; }
    [[nodiscard]] bool is_string() const { return type == kind::string; }
    [[nodiscard]] bool is_number() const { return type == kind::number; }
    [[nodiscard]] bool is_bool() const { return type == kind::boolean; }

    /// Member lookup (objects only); nullptr when absent or when this is not an object.
    [[nodiscard]] const json_value* find(std::string_view key) const {
        if (type != kind::object) return nullptr;
        const json_value* found = nullptr;
        for (std::size_t i = 0; i < keys.size(); ++i)
            if (keys[i] == key) found = &values[i];
        return found;
    }
};

inline constexpr int json_max_depth = 256;

namespace detail {

class json_parser {
public:
    explicit json_parser(std::string_view text) : s_(text) {}

    json_value parse_document() {
        skip_ws();
        if (pos_ >= s_.size()) fail("empty input (no JSON value)");
        json_value v = parse_value(0);
        skip_ws();
        if (pos_ < s_.size()) fail("unexpected characters after the JSON value");
        return v;
    }

private:
    std::string_view s_;
    std::size_t pos_ = 0;

    [[noreturn]] void fail(const std::string& what) const {
        std::size_t line = 1, col = 1;
        for (std::size_t i = 0; i < pos_ && i < s_.size(); ++i) {
            if (s_[i] == '\n') {
                ++line;
                col = 1;
            } else {
                ++col;
            }
        }
        throw json_error(std::to_string(line) + ":" + std::to_string(col) + ": " + what);
    }

    [[nodiscard]] bool at_end() const { return pos_ >= s_.size(); }
    [[nodiscard]] char peek() const { return at_end() ? '\0' : s_[pos_]; }

    void skip_ws() {
        while (!at_end() && (s_[pos_] == ' ' || s_[pos_] == '\t' || s_[pos_] == '\n' || s_[pos_] == '\r')) ++pos_;
    }

    void expect(char c, const char* context) {
        if (peek() != c || at_end()) fail(std::string("expected '") + c + "' " + context);
        ++pos_;
    }

    bool consume_literal(std::string_view lit) {
        if (s_.substr(pos_, lit.size()) == lit) {
            pos_ += lit.size();
            return true;
        }
        return false;
    }

    json_value parse_value(int depth) {
        if (depth > json_max_depth) fail("nesting deeper than " + std::to_string(json_max_depth));
        skip_ws();
        if (at_end()) fail("unexpected end of input, expected a value");
        json_value v;
        const char c = s_[pos_];
        if (c == '{') {
            parse_object(v, depth);
        } else if (c == '[') {
            parse_array(v, depth);
        } else if (c == '"') {
            v.type = json_value::kind::string;
            v.string = parse_string();
        } else if (consume_literal("true")) {
            v.type = json_value::kind::boolean;
            v.boolean = true;
        } else if (consume_literal("false")) {
            v.type = json_value::kind::boolean;
        } else if (consume_literal("null")) {
            v.type = json_value::kind::null;
        } else if (c == '-' || (c >= '0' && c <= '9') || c == 'N' || c == 'I') {
            v.type = json_value::kind::number;
            v.number = parse_number();
        } else {
            fail(std::string("unexpected character '") + printable(c) + "', expected a value");
        }
        return v;
    }

    static std::string printable(char c) {
        const auto u = static_cast<unsigned char>(c);
        if (u >= 32 && u < 127) return std::string(1, c);
        static const char* hex = "0123456789abcdef";
        return std::string("\\x") + hex[u >> 4] + hex[u & 15];
    }

    void parse_object(json_value& v, int depth) {
        v.type = json_value::kind::object;
        ++pos_; // '{'
        skip_ws();
        if (peek() == '}') {
            ++pos_;
            return;
        }
        for (;;) {
            skip_ws();
            if (peek() != '"') fail("expected a string key in object");
            std::string key = parse_string();
            skip_ws();
            expect(':', "after an object key");
            json_value member = parse_value(depth + 1);
            v.keys.push_back(std::move(key));
            v.values.push_back(std::move(member));
            skip_ws();
            if (peek() == ',' && !at_end()) {
                ++pos_;
                continue;
            }
            if (peek() == '}' && !at_end()) {
                ++pos_;
                return;
            }
            fail(at_end() ? "unexpected end of input in object" : "expected ',' or '}' in object");
        }
    }

    void parse_array(json_value& v, int depth) {
        v.type = json_value::kind::array;
        ++pos_; // '['
        skip_ws();
        if (peek() == ']') {
            ++pos_;
            return;
        }
        for (;;) {
            v.values.push_back(parse_value(depth + 1));
            skip_ws();
            if (peek() == ',' && !at_end()) {
                ++pos_;
                continue;
            }
            if (peek() == ']' && !at_end()) {
                ++pos_;
                return;
            }
            fail(at_end() ? "unexpected end of input in array" : "expected ',' or ']' in array");
        }
    }

    unsigned parse_hex4() {
        unsigned u = 0;
        for (int i = 0; i < 4; ++i) {
            if (at_end()) fail("unexpected end of input in \\u escape");
            const char c = s_[pos_++];
            u <<= 4;
            if (c >= '0' && c <= '9') u |= unsigned(c - '0');
            else if (c >= 'a' && c <= 'f') u |= unsigned(c - 'a' + 10);
            else if (c >= 'A' && c <= 'F') u |= unsigned(c - 'A' + 10);
            else fail("invalid hex digit in \\u escape");
        }
        return u;
    }

    static void append_utf8(std::string& out, std::uint32_t cp) {
        if (cp < 0x80) {
            out += char(cp);
        } else if (cp < 0x800) {
            out += char(0xC0 | (cp >> 6));
            out += char(0x80 | (cp & 0x3F));
        } else if (cp < 0x10000) {
            out += char(0xE0 | (cp >> 12));
            out += char(0x80 | ((cp >> 6) & 0x3F));
            out += char(0x80 | (cp & 0x3F));
        } else {
            out += char(0xF0 | (cp >> 18));
            out += char(0x80 | ((cp >> 12) & 0x3F));
            out += char(0x80 | ((cp >> 6) & 0x3F));
            out += char(0x80 | (cp & 0x3F));
        }
    }

    std::string parse_string() {
        ++pos_; // opening quote
        std::string out;
        for (;;) {
            if (at_end()) fail("unterminated string");
            const char c = s_[pos_];
            if (c == '"') {
                ++pos_;
                return out;
            }
            if (static_cast<unsigned char>(c) < 0x20) fail("control character in string (must be escaped)");
            if (c != '\\') {
                out += c;
                ++pos_;
                continue;
            }
            ++pos_;
            if (at_end()) fail("unterminated escape in string");
            const char e = s_[pos_++];
            switch (e) {
            case '"': out += '"'; break;
            case '\\': out += '\\'; break;
            case '/': out += '/'; break;
            case 'b': out += '\b'; break;
            case 'f': out += '\f'; break;
            case 'n': out += '\n'; break;
            case 'r': out += '\r'; break;
            case 't': out += '\t'; break;
            case 'u': {
                std::uint32_t cp = parse_hex4();
                if (cp >= 0xD800 && cp <= 0xDBFF) {
                    if (!consume_literal("\\u")) fail("high surrogate without a following \\u low surrogate");
                    const std::uint32_t lo = parse_hex4();
                    if (lo < 0xDC00 || lo > 0xDFFF) fail("invalid low surrogate in \\u escape");
                    cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
                } else if (cp >= 0xDC00 && cp <= 0xDFFF) {
                    fail("lone low surrogate in \\u escape");
                }
                append_utf8(out, cp);
                break;
            }
            default: --pos_; fail(std::string("invalid escape '\\") + printable(e) + "' in string");
            }
        }
    }

    double parse_number() {
        // Google Benchmark's spellings of non-finite counters.
        const bool neg = peek() == '-';
        const std::size_t start = pos_;
        if (neg) ++pos_;
        if (consume_literal("NaN")) return std::numeric_limits<double>::quiet_NaN();
        if (consume_literal("Infinity"))
            return neg ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
        auto digits = [&] {
            const std::size_t b = pos_;
            while (!at_end() && s_[pos_] >= '0' && s_[pos_] <= '9') ++pos_;
            return pos_ - b;
        };
        if (peek() == '0' && !at_end()) {
            ++pos_;
        } else if (digits() == 0) {
            fail("invalid number");
        }
        if (peek() == '.' && !at_end()) {
            ++pos_;
            if (digits() == 0) fail("invalid number: digits expected after '.'");
        }
        if ((peek() == 'e' || peek() == 'E') && !at_end()) {
            ++pos_;
            if ((peek() == '+' || peek() == '-') && !at_end()) ++pos_;
            if (digits() == 0) fail("invalid number: digits expected in exponent");
        }
        // The token is validated; strtod on a bounded copy (the view is not NUL-terminated).
        const std::string token(s_.substr(start, pos_ - start));
        return std::strtod(token.c_str(), nullptr);
    }
};

} // namespace detail

/// Parses a whole document; throws json_error("line:col: what") on malformed input.
inline json_value parse_json(std::string_view text) { return detail::json_parser(text).parse_document(); }

} // namespace ibl_examples
