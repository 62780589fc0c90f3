#include "reports/html_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>

#include "analysis/link_run_wave.h"
#include "reports/sweep_report.h"

namespace isolink::reports {

using nlohmann::ordered_json;

std::string html_escape(std::string_view s) {
  std::string out;
  out.reserve(s.size() + s.size() / 8);
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string base64(std::span<const uint8_t> b) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((b.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 3 <= b.size(); i += 3) {
    const uint32_t v = (uint32_t{b[i]} << 16) | (uint32_t{b[i + 1]} << 8) | b[i + 2];
    for (int k = 18; k >= 0; k -= 6) out += kAlphabet[(v >> k) & 63];
  }
  if (const size_t rest = b.size() - i; rest > 0) {
    const uint32_t v = (uint32_t{b[i]} << 16) | (rest == 2 ? uint32_t{b[i + 1]} << 8 : 0);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += rest == 2 ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string png_data_uri(const std::string& png) {
  if (png.empty()) return "";
  return "data:image/png;base64," +
         base64({reinterpret_cast<const uint8_t*>(png.data()), png.size()});
}

std::string script_json(const ordered_json& j) {
  // Non-finite numbers never reach the page: nlohmann writes them as null.
  const std::string s = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string out;
  out.reserve(s.size());
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '<' && i + 1 < s.size() && s[i + 1] == '/') {
      out += "<\\/";
      ++i;
    } else {
      out += s[i];
    }
  }
  return out;
}

std::string html_page(const std::string& kind, const std::string& title, const ordered_json& data) {
  // The data (tens of MB for a long record) joins a page reserved to its size: appended to a
  // growing string it would be held up to three times over.
  const std::string json = script_json(data);
  std::string p;
  p.reserve(json.size() + detail::dygraph_css().size() + detail::page_css().size() +
            detail::dygraph_js().size() + detail::page_js().size() + 4096);
  p += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  p += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  p += "<title>" + html_escape(title) + "</title>\n<style>\n";
  p += detail::dygraph_css();
  p += "\n";
  p += detail::page_css();
  p += "</style>\n</head>\n";
  p += "<body data-kind=\"" + html_escape(kind) + "\" data-ready=\"0\">\n";
  p += "<noscript><p class=\"noscript\">This report draws its plots with JavaScript; report.md "
       "beside this file has the same figures.</p></noscript>\n";
  p += "<main id=\"app\"></main>\n";
  p += "<script type=\"application/json\" id=\"isolink-data\">";
  p += json;
  p += "</script>\n<script>\n";
  p += detail::dygraph_js();
  p += "\n</script>\n<script>\n";
  p += detail::page_js();
  p += "\n</script>\n</body>\n</html>\n";
  return p;
}

std::vector<size_t> minmax_keep(std::span<const double> v, size_t max_samples) {
  const size_t n = v.size();
  std::vector<size_t> keep;
  if (n <= max_samples || max_samples < 2) {
    keep.resize(n);
    for (size_t i = 0; i < n; ++i) keep[i] = i;
    return keep;
  }
  const size_t buckets = max_samples / 2;
  keep.reserve(buckets * 2);
  for (size_t b = 0; b < buckets; ++b) {
    const size_t i0 = b * n / buckets, i1 = (b + 1) * n / buckets;
    size_t lo = i0, hi = i0;
    for (size_t i = i0; i < i1; ++i) {
      if (v[i] < v[lo]) lo = i;
      if (v[i] > v[hi]) hi = i;
    }
    keep.push_back(std::min(lo, hi));
    if (hi != lo) keep.push_back(std::max(lo, hi));
  }
  return keep;
}

namespace {

template <typename T>
std::string base64_of(const std::vector<T>& v) {
  return base64({reinterpret_cast<const uint8_t*>(v.data()), v.size() * sizeof(T)});
}

// Whether t[i] = t[0] + i dt within 1e-6 of dt for every sample but the last, which may lie off
// the grid (a record ends where the simulation stopped; its time is sent as t_last).
bool uniform_grid(std::span<const double> t, double* dt) {
  if (t.size() < 3) return false;
  const size_t n = t.size() - 1;  // the samples on the grid
  *dt = (t[n - 1] - t.front()) / static_cast<double>(n - 1);
  if (!(*dt > 0) || !(t[n] > t[n - 1])) return false;
  for (size_t i = 0; i < n; ++i)
    if (std::abs(t[i] - (t.front() + static_cast<double>(i) * *dt)) > 1e-6 * *dt) return false;
  return true;
}

}  // namespace

size_t wave_samples_for(size_t bytes, double span) {
  return span > kFloat32TimeSpan ? bytes * 3 / 48 : bytes * 3 / 32;
}

namespace {

// The samples kept of a record longer than max_samples: thinned with the finest tolerance that
// fits (*tolerance set), else min/max buckets (*tolerance 0). Each tolerance's samples are
// counted first: the indices of a 25 ms record at 1 mV took 200 MB beside it.
std::vector<size_t> reduce_wave(std::span<const double> t, std::span<const double> v,
                                size_t max_samples, double* tolerance) {
  const size_t k = analysis::finest_fitting(kHtmlThinTolerances, [&](double tol) {
    return analysis::thin_rows_count(t, {v}, tol) <= max_samples;
  });
  if (k < std::size(kHtmlThinTolerances)) {
    *tolerance = kHtmlThinTolerances[k];
    return analysis::thin_rows(t, {v}, *tolerance);
  }
  *tolerance = 0;
  return minmax_keep(v, max_samples);
}

}  // namespace

ordered_json wave_json(const HtmlWave& w, size_t max_samples) {
  const size_t n = std::min(w.time.size(), w.values.size());
  if (n == 0) return {{"direction", w.direction}, {"samples", 0}, {"kept", 0}};
  const std::span<const double> t = w.time.first(n), v = w.values.first(n);
  double tolerance = 0;
  std::vector<size_t> keep;
  if (n <= max_samples) {
    keep.resize(n);
    for (size_t i = 0; i < n; ++i) keep[i] = i;
  } else {
    keep = reduce_wave(t, v, max_samples, &tolerance);
  }
  std::vector<float> vf(keep.size());
  for (size_t k = 0; k < keep.size(); ++k)
    vf[k] = std::isfinite(v[keep[k]]) ? static_cast<float>(v[keep[k]])
                                      : std::numeric_limits<float>::quiet_NaN();
  ordered_json j{{"direction", w.direction}, {"samples", n}, {"kept", keep.size()}};
  double dt = 0;
  const double t0 = t[keep.front()];
  if (keep.size() == n && uniform_grid(t, &dt)) {
    j["t0"] = t.front();
    j["dt"] = dt;
    j["t_last"] = t.back();
  } else if (t.back() - t0 <= kFloat32TimeSpan) {
    // Times as Float32 offsets from the first: 6 ps resolution over 100 us, half the bytes of
    // Float64.
    std::vector<float> tk(keep.size());
    for (size_t k = 0; k < keep.size(); ++k) tk[k] = static_cast<float>(t[keep[k]] - t0);
    j["t0"] = t0;
    j["t"] = base64_of(tk);
  } else {
    std::vector<double> tk(keep.size());
    for (size_t k = 0; k < keep.size(); ++k) tk[k] = t[keep[k]] - t0;
    j["t0"] = t0;
    j["t64"] = base64_of(tk);
  }
  j["v"] = base64_of(vf);
  if (keep.size() < n) {
    if (tolerance > 0)
      j["tolerance"] = tolerance;
    else
      j["buckets"] = true;
  }
  return j;
}

std::string run_report_html(const ordered_json& report, const ordered_json& extra,
                            const std::vector<HtmlWave>& waves, const std::string& eye_png) {
  ordered_json data{{"report", report}, {"extra", extra}};
  ordered_json wj = ordered_json::array();
  // A wave equal to an earlier one (both directions of a symmetric link) is embedded once.
  auto same = [&](size_t i) -> std::optional<size_t> {
    for (size_t k = 0; k < i; ++k)
      if (std::ranges::equal(waves[k].time, waves[i].time) &&
          std::ranges::equal(waves[k].values, waves[i].values))
        return k;
    return std::nullopt;
  };
  size_t distinct = 0;
  for (size_t i = 0; i < waves.size(); ++i) distinct += same(i) ? 0 : 1;
  // The byte budget shared by the waves; a non-uniform record also pays for its times.
  const size_t share = kHtmlWaveBytes / std::max<size_t>(distinct, 1);
  for (size_t i = 0; i < waves.size(); ++i) {
    const HtmlWave& w = waves[i];
    if (const std::optional<size_t> k = same(i)) {
      wj.push_back({{"direction", w.direction}, {"same_as", *k}});
      continue;
    }
    double dt = 0;
    const size_t whole = share * 3 / 16;  // samples a uniform grid may keep whole
    const bool fits = w.time.size() <= whole && uniform_grid(w.time, &dt);
    const double span = w.time.empty() ? 0.0 : w.time.back() - w.time.front();
    wj.push_back(wave_json(w, fits ? whole : wave_samples_for(share, span)));
  }
  data["waves"] = std::move(wj);
  data["eye"] = png_data_uri(eye_png);
  const std::string name = report.contains("name") ? report["name"].get<std::string>() : "";
  return html_page("run", "isolink report: " + name, data);
}

std::string sweep_report_html(const analysis::sweep::SweepSpec& s,
                              const std::vector<analysis::sweep::PointResult>& results) {
  const SweepPlotData d = sweep_plot_data(s, results);
  ordered_json axes = ordered_json::array();
  for (const SweepPlotAxis& a : d.axes)
    axes.push_back({{"name", a.name},
                    {"unit", a.unit},
                    {"labels", a.labels},
                    {"values", a.values},
                    {"log", a.log}});
  ordered_json points = ordered_json::array();
  for (size_t i = 0; i < results.size() && i < d.points.size(); ++i) {
    const analysis::sweep::PointResult& r = results[i];
    points.push_back({{"index", r.index},
                      {"cells", r.cells},
                      {"axis", d.points[i].axis},
                      {"verdict", r.verdict},
                      {"worst_metric", r.worst_metric},
                      {"margin", std::isfinite(r.worst_rel) ? ordered_json(r.worst_rel) : nullptr},
                      {"reason", r.reason},
                      {"error", r.error},
                      {"seconds", r.seconds}});
  }
  const ordered_json data{{"title", d.title},     {"source", d.source},           {"note", d.note},
                          {"samples", d.samples}, {"columns", s.point_columns()}, {"axes", axes},
                          {"points", points}};
  return html_page("sweep", "isolink sweep: " + d.title, data);
}

std::string pack_report_html(const ordered_json& report, const std::string& pack_png) {
  const ordered_json data{{"report", report}, {"diagram", png_data_uri(pack_png)}};
  const std::string name = report.contains("name") ? report["name"].get<std::string>() : "";
  return html_page("pack", "isolink pack: " + name, data);
}

ordered_json stress_pins_json(const analysis::StressScenario& s, size_t max_samples) {
  const Waveform& w = s.pins;
  const size_t n = w.samples();
  std::vector<size_t> keep;
  if (n <= max_samples || w.columns.empty()) {
    keep.resize(n);
    for (size_t i = 0; i < n; ++i) keep[i] = i;
  } else {
    const size_t per_pin = std::max<size_t>(4, max_samples / w.columns.size());
    for (const std::vector<double>& col : w.columns) {
      const std::vector<size_t> k = minmax_keep(col, per_pin);
      keep.insert(keep.end(), k.begin(), k.end());
    }
    keep.push_back(0);
    keep.push_back(n - 1);
    std::sort(keep.begin(), keep.end());
    keep.erase(std::unique(keep.begin(), keep.end()), keep.end());
  }
  std::vector<double> t(keep.size());
  for (size_t i = 0; i < keep.size(); ++i) t[i] = w.time[keep[i]];
  ordered_json pins = ordered_json::object();
  for (size_t k = 0; k < w.columns.size() && k < w.names.size(); ++k) {
    std::vector<float> v(keep.size());
    for (size_t i = 0; i < keep.size(); ++i) {
      const double x = w.columns[k][keep[i]];
      v[i] = std::isfinite(x) ? static_cast<float>(x) : std::numeric_limits<float>::quiet_NaN();
    }
    pins[w.names[k]] = base64_of(v);
  }
  return {{"t", base64_of(t)}, {"pins", pins}, {"samples", n}, {"kept", keep.size()}};
}

std::string stress_report_html(const ordered_json& report, const std::string& stress_png,
                               const analysis::StressResult& r) {
  ordered_json pins = ordered_json::object();
  for (const analysis::StressScenario& s : r.scenarios)
    pins[s.id] = stress_pins_json(s, kStressPinSamples);
  const ordered_json data{{"report", report}, {"image", png_data_uri(stress_png)}, {"pins", pins}};
  const std::string name = report.contains("spec") ? report["spec"].get<std::string>() : "";
  return html_page("stress", "isolink stress: " + name, data);
}

}  // namespace isolink::reports
