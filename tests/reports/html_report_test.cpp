#include "reports/html_report.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <iterator>
#include <string>
#include <vector>

#include "analysis/link_run_wave.h"

namespace isolink::reports {
namespace {

using nlohmann::ordered_json;

std::vector<uint8_t> unbase64(const std::string& s) {
  auto val = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    return c == '+' ? 62 : c == '/' ? 63 : -1;
  };
  std::vector<uint8_t> out;
  uint32_t acc = 0;
  int bits = 0;
  for (char c : s) {
    const int v = val(c);
    if (v < 0) break;
    acc = (acc << 6) | static_cast<uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<uint8_t>((acc >> bits) & 0xFF));
    }
  }
  return out;
}

template <typename T>
std::vector<T> decode(const std::string& b64) {
  const std::vector<uint8_t> b = unbase64(b64);
  std::vector<T> v(b.size() / sizeof(T));
  std::memcpy(v.data(), b.data(), v.size() * sizeof(T));
  return v;
}

// The JSON data block of a page.
nlohmann::json page_data(const std::string& page) {
  const size_t a = page.find("id=\"isolink-data\">") + 18, b = page.find("</script>", a);
  return nlohmann::json::parse(page.substr(a, b - a));
}

TEST(HtmlReport, Base64MatchesRfc4648) {
  // The test vectors of RFC 4648 section 10.
  const std::vector<std::pair<std::string, std::string>> cases = {{"", ""},
                                                                  {"f", "Zg=="},
                                                                  {"fo", "Zm8="},
                                                                  {"foo", "Zm9v"},
                                                                  {"foob", "Zm9vYg=="},
                                                                  {"fooba", "Zm9vYmE="},
                                                                  {"foobar", "Zm9vYmFy"}};
  for (const auto& [in, out] : cases)
    EXPECT_EQ(base64({reinterpret_cast<const uint8_t*>(in.data()), in.size()}), out) << in;
  const std::vector<uint8_t> all = [] {
    std::vector<uint8_t> v(256);
    for (int i = 0; i < 256; ++i) v[static_cast<size_t>(i)] = static_cast<uint8_t>(i);
    return v;
  }();
  EXPECT_EQ(unbase64(base64(all)), all);
}

TEST(HtmlReport, EscapesTextAndScriptJson) {
  EXPECT_EQ(html_escape("a<b & \"c\" 'd'>"), "a&lt;b &amp; &quot;c&quot; &#39;d&#39;&gt;");
  const ordered_json j{{"name", "x</script><script>alert(1)</script>"}, {"v", NAN}};
  const std::string s = script_json(j);
  EXPECT_EQ(s.find("</"), std::string::npos) << s;
  const nlohmann::json back = nlohmann::json::parse(s);  // still the same JSON
  EXPECT_EQ(back["name"], "x</script><script>alert(1)</script>");
  EXPECT_TRUE(back["v"].is_null());  // non-finite numbers never reach the page
}

// A one-sample spike in a million samples survives the min/max reduction, and the kept indices
// run in time order.
TEST(HtmlReport, MinMaxKeepsEveryExcursion) {
  std::vector<double> v(1'000'000);
  for (size_t i = 0; i < v.size(); ++i) v[i] = std::sin(static_cast<double>(i) * 1e-3);
  v[654'321] = 7.5;
  v[123'457] = -6.25;
  const std::vector<size_t> keep = minmax_keep(v, 20'000);
  EXPECT_LE(keep.size(), 20'000u);
  EXPECT_GE(keep.size(), 19'000u);
  for (size_t k = 1; k < keep.size(); ++k) ASSERT_LT(keep[k - 1], keep[k]);
  EXPECT_NE(std::find(keep.begin(), keep.end(), 654'321u), keep.end());
  EXPECT_NE(std::find(keep.begin(), keep.end(), 123'457u), keep.end());
  EXPECT_EQ(minmax_keep(std::vector<double>(50, 1.0), 100).size(), 50u);
}

TEST(HtmlReport, WaveJsonRoundTrips) {
  std::vector<double> t(1000), v(1000);
  for (size_t i = 0; i < t.size(); ++i) {
    t[i] = 2e-6 + static_cast<double>(i) * 1e-9;
    v[i] = 1.7 * std::sin(static_cast<double>(i) * 0.01);
  }
  // A uniform grid: t0 and dt, values as Float32.
  ordered_json j = wave_json({"down", t, v}, 10'000);
  EXPECT_EQ(j["samples"], 1000);
  EXPECT_EQ(j["kept"], 1000);
  EXPECT_NEAR(j["t0"].get<double>(), 2e-6, 1e-18);
  EXPECT_NEAR(j["dt"].get<double>(), 1e-9, 1e-21);
  EXPECT_FALSE(j.contains("t"));
  std::vector<float> vf = decode<float>(j["v"].get<std::string>());
  ASSERT_EQ(vf.size(), 1000u);
  for (size_t i = 0; i < v.size(); ++i) ASSERT_NEAR(vf[i], v[i], 1e-6);
  EXPECT_NEAR(j["t_last"].get<double>(), t.back(), 1e-18);
  // A record that stops between grid points is still a grid, with its last time given.
  std::vector<double> cut = t;
  cut.back() = cut[998] + 0.4e-9;
  j = wave_json({"down", cut, v}, 10'000);
  ASSERT_TRUE(j.contains("dt"));
  EXPECT_EQ(j["t_last"].get<double>(), cut.back());
  // Both directions of a symmetric link: the samples once, the second refers to the first.
  const nlohmann::json data = page_data(
      run_report_html({{"name", "x"}}, ordered_json::object(), {{"down", t, v}, {"up", t, v}}, ""));
  ASSERT_EQ(data["waves"].size(), 2u);
  EXPECT_TRUE(data["waves"][0].contains("v"));
  EXPECT_EQ(data["waves"][1]["same_as"], 0);
  EXPECT_EQ(data["waves"][1]["direction"], "up");
  // Not uniform: the times as Float32 offsets from t0.
  t[500] += 0.3e-9;
  j = wave_json({"down", t, v}, 10'000);
  EXPECT_FALSE(j.contains("dt"));
  const std::vector<float> tt = decode<float>(j["t"].get<std::string>());
  ASSERT_EQ(tt.size(), 1000u);
  for (size_t i = 0; i < t.size(); ++i)  // within 1 ps here
    ASSERT_NEAR(j["t0"].get<double>() + tt[i], t[i], 1e-12) << i;
  // Reduced: at most the budget, thinned with the finest tolerance that fits. 1.7 sin(0.01 i): a
  // chord of k samples errs by up to 1.7 (0.01 k)^2 / 8 (at a crest), so 1 mV allows chords of 6.9
  // samples there; over the record 1 mV keeps more than 100 samples and 2 mV fewer.
  EXPECT_GT(analysis::thin_rows(t, {v}, 1e-3).size(), 100u);
  j = wave_json({"down", t, v}, 100);
  EXPECT_LE(j["kept"].get<size_t>(), 100u);
  EXPECT_GE(j["kept"].get<size_t>(), 60u);
  EXPECT_DOUBLE_EQ(j["tolerance"].get<double>(), 2e-3);
  vf = decode<float>(j["v"].get<std::string>());
  std::vector<float> off = decode<float>(j["t"].get<std::string>());
  ASSERT_EQ(off.size(), vf.size());
  for (size_t i = 0, k = 0; i < t.size(); ++i) {  // every sample within 2 mV of the kept line
    const double x = t[i] - j["t0"].get<double>();
    while (k + 2 < off.size() && off[k + 1] <= x) ++k;
    const double f = std::clamp((x - off[k]) / (off[k + 1] - off[k]), 0.0, 1.0);
    ASSERT_NEAR(vf[k] + f * (vf[k + 1] - vf[k]), v[i], 2e-3 + 1e-5) << i;
  }
  // Noise of 1 V that no tolerance up to 100 mV thins enough: min/max buckets, the extremes kept.
  for (size_t i = 0; i < v.size(); ++i)
    v[i] = static_cast<double>(i * 7919 % 1000) * 1e-3 - 0.5 + (i == 321 ? 3 : 0);
  j = wave_json({"down", t, v}, 100);
  EXPECT_LE(j["kept"].get<size_t>(), 100u);
  EXPECT_TRUE(j["buckets"].get<bool>());
  EXPECT_FALSE(j.contains("tolerance"));
  vf = decode<float>(j["v"].get<std::string>());
  // The spike at 321: 0.999 - 0.5 + 3 V.
  EXPECT_NEAR(*std::max_element(vf.begin(), vf.end()), 3.499, 1e-6);
}

// A record longer than 100 us carries Float64 time offsets: a 200 ms record resolves 1 ps.
TEST(HtmlReport, LongRecordsKeepTheirTimesToAPicosecond) {
  std::vector<double> t{0.0, 0.05, 0.2 - 1e-12, 0.2}, v{0, 1, 1, 0};
  const ordered_json j = wave_json({"down", t, v}, 100);
  ASSERT_TRUE(j.contains("t64"));
  const std::vector<double> off = decode<double>(j["t64"].get<std::string>());
  ASSERT_EQ(off.size(), 4u);
  EXPECT_NEAR(off[2], 0.2 - 1e-12, 1e-16);
  EXPECT_LT(off[2], off[3]);
  EXPECT_EQ(wave_samples_for(48'000, 1.0), 3000u);   // 16 base64 bytes a sample
  EXPECT_EQ(wave_samples_for(32'000, 1e-5), 3000u);  // 32/3
}

// The page is one file: the library and the script inlined, no network address of any kind, the
// data block intact, and data-ready="0" until the script has drawn.
TEST(HtmlReport, PageIsSelfContained) {
  const ordered_json report{
      {"verdict", "pass"}, {"name", "t</b>"}, {"directions", ordered_json::array()}};
  const std::string page = run_report_html(report, ordered_json::object(), {}, "");
  EXPECT_NE(page.find("<body data-kind=\"run\" data-ready=\"0\">"), std::string::npos);
  EXPECT_NE(page.find("Dygraph"), std::string::npos);
  EXPECT_GT(detail::dygraph_js().size(), 100'000u);
  EXPECT_NE(page.find("data-ready"), std::string::npos);
  EXPECT_NE(page.find("<title>isolink report: t&lt;/b&gt;</title>"), std::string::npos);
  // No network address: a plain substring scan of the lower-cased page (std::regex trips GCC 12's
  // maybe-uninitialized warning in the sanitizer build).
  std::string lower = page;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  std::string compact;  // whitespace dropped, so `src = "//` reads as `src="//`
  std::copy_if(lower.begin(), lower.end(), std::back_inserter(compact),
               [](unsigned char c) { return !std::isspace(c); });
  for (const char* address : {"http://", "https://", "ftp://", "ws://", "wss://", "@import",
                              "sourcemappingurl", "src=\"//", "src='//", "src=//"})
    EXPECT_EQ(compact.find(address), std::string::npos) << address;
  // One data block; what it holds parses back to what went in.
  EXPECT_EQ(page_data(page)["report"]["name"], "t</b>");
}

// A stress scenario's pins on the page: a 200,000-sample record is cut to at most
// kStressPinSamples, and every pin's highest and lowest sample (a one-sample spike among them)
// survives with its time; a short record is kept whole.
TEST(HtmlReport, StressPinsKeepEveryPeak) {
  analysis::StressScenario s;
  s.id = "esd_tx_p_pos";
  const size_t n = 200'000;
  for (size_t i = 0; i < n; ++i) s.pins.time.push_back(1e-9 * static_cast<double>(i));
  s.pins.names = {"txp", "rxp"};
  s.pins.columns.assign(2, std::vector<double>(n));
  for (size_t i = 0; i < n; ++i) {
    s.pins.columns[0][i] = 2.5 + std::sin(1e-3 * static_cast<double>(i));
    s.pins.columns[1][i] = 2.5;
  }
  s.pins.columns[1][123'457] = 17.25;  // one sample
  s.pins.columns[0][77] = -6.5;
  const ordered_json j = stress_pins_json(s, kStressPinSamples);
  EXPECT_EQ(j["samples"], n);
  const std::vector<double> t = decode<double>(j["t"].get<std::string>());
  const std::vector<float> txp = decode<float>(j["pins"]["txp"].get<std::string>());
  const std::vector<float> rxp = decode<float>(j["pins"]["rxp"].get<std::string>());
  ASSERT_EQ(t.size(), j["kept"].get<size_t>());
  ASSERT_LE(t.size(), kStressPinSamples + 2);
  ASSERT_EQ(txp.size(), t.size());
  ASSERT_EQ(rxp.size(), t.size());
  EXPECT_TRUE(std::is_sorted(t.begin(), t.end()));
  const auto spike = std::max_element(rxp.begin(), rxp.end());
  EXPECT_EQ(*spike, 17.25f);
  EXPECT_DOUBLE_EQ(t[static_cast<size_t>(spike - rxp.begin())], 123'457e-9);
  EXPECT_EQ(*std::min_element(txp.begin(), txp.end()), -6.5f);
  EXPECT_NEAR(*std::max_element(txp.begin(), txp.end()), 3.5, 1e-6);  // the sine's top
  EXPECT_EQ(t.front(), 0.0);
  EXPECT_DOUBLE_EQ(t.back(), 1e-9 * static_cast<double>(n - 1));
  s.pins.time.resize(100);
  for (auto& c : s.pins.columns) c.resize(100);
  EXPECT_EQ(stress_pins_json(s, kStressPinSamples)["kept"], 100u);
}

}  // namespace
}  // namespace isolink::reports
