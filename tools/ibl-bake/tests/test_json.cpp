// tools/ibl-bake/tests/test_json.cpp — the JSON writer: structure, number round trip,
// null for non-finite numbers, string escaping and UTF-8 repair, misuse.

#include <doctest/doctest.h>

#include "io/json.hpp"

#include <cstdlib>
#include <limits>
#include <random>
#include <string>

using ibl_bake::json_writer;

TEST_CASE("json: compact structure") {
    json_writer j(0);
    j.begin_object();
    j.key("order").value(3);
    j.key("name").value("studio");
    j.key("ok").value(true);
    j.key("coeffs").begin_array().value(1.5).value(-2).begin_array().end_array().end_array();
    j.key("empty").begin_object().end_object();
    j.key("nothing").null();
    j.end_object();
    CHECK(j.str() == R"({"order":3,"name":"studio","ok":true,"coeffs":[1.5,-2,[]],"empty":{},"nothing":null})");
}

TEST_CASE("json: indented structure") {
    json_writer j(2);
    j.begin_object().key("a").begin_array().value(1).value(2).end_array().end_object();
    CHECK(j.str() == "{\n  \"a\": [\n    1,\n    2\n  ]\n}");
}

TEST_CASE("json: numbers round-trip; non-finite numbers are null") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-300, 300);
    for (int i = 0; i < 2000; ++i) {
        const double d = std::pow(10.0, u(rng)) * (i % 2 ? 1 : -1);
        const float f = static_cast<float>(std::pow(10.0, u(rng) / 10));
        json_writer jd(0), jf(0);
        jd.value(d);
        jf.value(f);
        CHECK(std::strtod(jd.str().c_str(), nullptr) == d);
        CHECK(std::strtof(jf.str().c_str(), nullptr) == f);
    }
    json_writer a(0);
    a.begin_array().value(0.1f).value(0.1).value(1e-30f).value(std::numeric_limits<double>::quiet_NaN());
    a.value(std::numeric_limits<float>::infinity()).value(-std::numeric_limits<double>::infinity()).end_array();
    CHECK(a.str() == "[0.1,0.1,1e-30,null,null,null]");
    json_writer big(0);
    big.begin_array().value(std::uint64_t(18446744073709551615ull)).value(std::int64_t(-9223372036854775807ll - 1)).end_array();
    CHECK(big.str() == "[18446744073709551615,-9223372036854775808]");
}

TEST_CASE("json: string escaping and UTF-8 repair") {
    json_writer j(0);
    j.value(std::string("q\"b\\n\n\t\x01\x1f/é€𝄞"));
    CHECK(j.str() == "\"q\\\"b\\\\n\\n\\t\\u0001\\u001f/é€𝄞\"");
    json_writer bad(0);
    // Invalid: lone continuation byte, overlong "/" (C0 AF), surrogate (ED A0 80), truncated 3-byte.
    bad.value(std::string("a\x80" "b\xC0\xAF" "c\xED\xA0\x80" "d\xE2\x82"));
    CHECK(bad.str() == "\"a\xEF\xBF\xBD" "b\xEF\xBF\xBD\xEF\xBF\xBD" "c\xEF\xBF\xBD\xEF\xBF\xBD\xEF\xBF\xBD"
                       "d\xEF\xBF\xBD\xEF\xBF\xBD\"");
}

TEST_CASE("json: misuse is a logic_error") {
    json_writer j(0);
    j.begin_object();
    CHECK_THROWS_AS(j.value(1), std::logic_error); // value without key
    CHECK_THROWS_AS(j.end_array(), std::logic_error);
    CHECK_THROWS_AS((void)j.str(), std::logic_error); // incomplete
    j.key("k");
    CHECK_THROWS_AS(j.key("k2"), std::logic_error);
    CHECK_THROWS_AS(j.end_object(), std::logic_error); // key without value
    j.value(1).end_object();
    CHECK_THROWS_AS(j.begin_array(), std::logic_error); // second document
    CHECK(j.str() == R"({"k":1})");
}
