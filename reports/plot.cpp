#include "reports/plot.h"

#include <dlfcn.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <system_error>
#include <vector>

#include "base/file_io.h"
#include "netlists/link/cards.h"
#include "reports/image_plugin.h"

namespace isolink::reports {
namespace fs = std::filesystem;

// --- fonts and text ------------------------------------------------------------------------------

std::vector<std::string> font_search_dirs() {
  std::vector<std::string> dirs;
  if (const char* env = std::getenv("ISOLINK_FONT_DIR"); env && *env) dirs.emplace_back(env);
  for (const char* d :
       {"/usr/share/fonts/truetype/dejavu", "/usr/share/fonts/dejavu", "/usr/share/fonts/TTF",
        "/usr/share/fonts/truetype", "/usr/local/share/fonts", "/usr/share/fonts",
        "/opt/homebrew/share/fonts", "/Library/Fonts"})
    dirs.emplace_back(d);
  if (const char* home = std::getenv("HOME"); home && *home) {
    dirs.push_back(std::string(home) + "/.local/share/fonts");
    dirs.push_back(std::string(home) + "/.fonts");
  }
  return dirs;
}

StatusOr<Fonts> find_fonts() {
  return find_fonts_in(font_search_dirs());
}

StatusOr<Fonts> find_fonts_in(const std::vector<std::string>& dirs) {
  static const char* kFiles[3] = {"DejaVuSans.ttf", "DejaVuSans-Bold.ttf", "DejaVuSansMono.ttf"};
  std::vector<std::string> looked;
  for (const std::string& base : dirs) {
    for (const std::string& dir : {base, base + "/dejavu"}) {
      looked.push_back(dir);
      std::error_code ec;
      bool all = true;
      for (const char* f : kFiles) all = all && fs::is_regular_file(fs::path(dir) / f, ec);
      if (!all) continue;
      Fonts out;
      out.dir = dir;
      out.sans = (fs::path(dir) / kFiles[0]).string();
      out.bold = (fs::path(dir) / kFiles[1]).string();
      out.mono = (fs::path(dir) / kFiles[2]).string();
      return out;
    }
  }
  std::string where;
  for (const std::string& d : looked) where += (where.empty() ? "" : ", ") + d;
  return Status::Error(fmt::format(
      "report fonts not found: need DejaVuSans.ttf, DejaVuSans-Bold.ttf and DejaVuSansMono.ttf "
      "in one directory (Debian: apt-get install fonts-dejavu-core, or set ISOLINK_FONT_DIR); "
      "looked in {}",
      where));
}

std::string ascii_text(std::string_view s) {
  static const std::pair<std::string_view, std::string_view> kMap[] = {
      {"\xC2\xB5", "u"},       {"\xCE\xBC", "u"},       {"\xC2\xB1", "+/-"},
      {"\xE2\x89\xA4", "<="},  {"\xE2\x89\xA5", ">="},  {"\xE2\x80\x93", "-"},
      {"\xE2\x80\x94", "-"},   {"\xE2\x88\x92", "-"},   {"\xE2\x86\x92", "->"},
      {"\xE2\x86\x90", "<-"},  {"\xC2\xB7", "|"},       {"\xC2\xB0", "deg"},
      {"\xCE\xA9", "ohm"},     {"\xE2\x84\xA6", "ohm"}, {"\xC3\x97", "x"},
      {"\xE2\x80\xA6", "..."},
  };
  std::string out;
  out.reserve(s.size());
  for (size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) {
      out += (c >= 0x20 || c == '\n') ? static_cast<char>(c) : ' ';
      ++i;
      continue;
    }
    bool done = false;
    for (const auto& [from, to] : kMap)
      if (s.substr(i, from.size()) == from) {
        out += to;
        i += from.size();
        done = true;
        break;
      }
    if (done) continue;
    size_t len = c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : c >= 0xC0 ? 2 : 1;
    out += '?';
    i += len;
  }
  return out;
}

// --- geometry ------------------------------------------------------------------------------------

int Axis::pixel(double v) const {
  return static_cast<int>(std::floor(to_px(v)));
}

PlotArea PlotArea::make(Rect r, double x_lo, double x_hi, double y_lo, double y_hi) {
  PlotArea a;
  a.rect = r;
  a.x = Axis{x_lo, x_hi, static_cast<double>(r.x0), static_cast<double>(r.x1)};
  a.y = Axis{y_lo, y_hi, static_cast<double>(r.y1), static_cast<double>(r.y0)};
  return a;
}

Rect PlotArea::data_rect(double x0, double x1, double y0, double y1) const {
  const double px0 = std::min(px(x0), px(x1)), px1 = std::max(px(x0), px(x1));
  const double py0 = std::min(py(y0), py(y1)), py1 = std::max(py(y0), py(y1));
  Rect r{static_cast<int>(std::lround(px0)), static_cast<int>(std::lround(py0)),
         static_cast<int>(std::lround(px1)), static_cast<int>(std::lround(py1))};
  r.x0 = std::clamp(r.x0, rect.x0, rect.x1);
  r.x1 = std::clamp(r.x1, rect.x0, rect.x1);
  r.y0 = std::clamp(r.y0, rect.y0, rect.y1);
  r.y1 = std::clamp(r.y1, rect.y0, rect.y1);
  return r;
}

// --- canvas --------------------------------------------------------------------------------------

namespace {

// Rounded half away from zero as std::lround, whose libm call was a third of a chart's drawing
// time (the value is non-negative, and its sum with 0.5 exact in double).
uint8_t to_byte(float v) {
  return static_cast<uint8_t>(static_cast<double>(std::clamp(v, 0.0f, 1.0f) * 255.0f) + 0.5);
}

Rect intersect(const Rect& a, const Rect& b) {
  return {std::max(a.x0, b.x0), std::max(a.y0, b.y0), std::min(a.x1, b.x1), std::min(a.y1, b.y1)};
}

bool dash_on(const LineStyle& s, double u) {
  if (!(s.dash > 0)) return true;
  const double period = s.dash + std::max(s.gap, 0.0);
  const double m = std::fmod(u, period);
  return (m < 0 ? m + period : m) < s.dash;
}

// The image plug-in (image_plugin.h), loaded once, on the first Canvas::create: from
// $ISOLINK_PLUGIN_DIR when set, else next to the executable, in ../lib/isolink beside it (an
// installed tree), or in the build tree it was built in (tests, the Python module).
struct ImagePlugin {
  const IsolinkImageApi* api = nullptr;
  std::string error;
};

const ImagePlugin& image_plugin() {
  static const ImagePlugin plugin = [] {
    ImagePlugin out;
    std::vector<fs::path> dirs;
    if (const char* env = std::getenv("ISOLINK_PLUGIN_DIR"); env && *env) dirs.emplace_back(env);
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) {
      dirs.push_back(exe.parent_path());
      dirs.push_back((exe.parent_path() / "../lib/isolink").lexically_normal());
    }
    dirs.emplace_back(ISOLINK_IMAGE_PLUGIN_BUILD_DIR);
    std::string looked;
    for (const fs::path& d : dirs) {
      const fs::path file = d / ISOLINK_IMAGE_PLUGIN_FILE;
      looked += (looked.empty() ? "" : ", ") + d.string();
      if (!fs::is_regular_file(file, ec)) continue;
      void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!handle) {
        out.error = fmt::format("cannot load the image plug-in {}: {}", file.string(), dlerror());
        return out;
      }
      auto entry = reinterpret_cast<IsolinkImageApiFn>(dlsym(handle, "isolink_image_api"));
      const IsolinkImageApi* api = entry ? entry() : nullptr;
      if (!api || api->version != kImagePluginVersion) {
        out.error =
            fmt::format("image plug-in {} is from another isolink build (interface {}, need {})",
                        file.string(), api ? api->version : 0, kImagePluginVersion);
        return out;
      }
      out.api = api;
      return out;
    }
    out.error = fmt::format(
        "the image plug-in {} (built with isolink; it draws the PNGs) was not "
        "found; looked in {} (or set ISOLINK_PLUGIN_DIR)",
        ISOLINK_IMAGE_PLUGIN_FILE, looked);
    return out;
  }();
  return plugin;
}

}  // namespace

void load_image_plugin() {
  image_plugin();
}

namespace {

struct Box {
  bool defined = false;
  int xbegin = 0, xend = 0, ybegin = 0, yend = 0;
};

Box text_box(const std::string& text, int size, const std::string& font) {
  const IsolinkImageApi* api = image_plugin().api;
  int b[4] = {0, 0, 0, 0};
  if (!api || !api->text_size(text.c_str(), size, font.c_str(), b)) return {};
  return {true, b[0], b[1], b[2], b[3]};
}

}  // namespace

StatusOr<Canvas> Canvas::create(int width, int height, Color background) {
  if (width <= 0 || height <= 0 || width > 20000 || height > 20000)
    return Status::Error(fmt::format("bad image size {} x {}", width, height));
  StatusOr<Fonts> f = find_fonts();
  if (!f) return f.status();
  if (!image_plugin().api) return Status::Error(image_plugin().error);
  Canvas c;
  c.w_ = width;
  c.h_ = height;
  c.fonts_ = *f;
  c.px_.resize(static_cast<size_t>(width) * static_cast<size_t>(height) * 3);
  const uint8_t r = to_byte(background.r), g = to_byte(background.g), b = to_byte(background.b);
  for (size_t i = 0; i < c.px_.size(); i += 3) {
    c.px_[i] = r;
    c.px_[i + 1] = g;
    c.px_[i + 2] = b;
  }
  return c;
}

Color Canvas::pixel(int x, int y) const {
  if (x < 0 || y < 0 || x >= w_ || y >= h_) return {};
  const size_t i = (static_cast<size_t>(y) * w_ + x) * 3;
  return {px_[i] / 255.0f, px_[i + 1] / 255.0f, px_[i + 2] / 255.0f, 1.0f};
}

void Canvas::blend(int x, int y, Color c, float coverage) {
  if (x < 0 || y < 0 || x >= w_ || y >= h_) return;
  const float a = std::clamp(c.a * coverage, 0.0f, 1.0f);
  if (a <= 0) return;
  uint8_t* p = &px_[(static_cast<size_t>(y) * w_ + x) * 3];
  if (a >= 1) {
    p[0] = to_byte(c.r);
    p[1] = to_byte(c.g);
    p[2] = to_byte(c.b);
    return;
  }
  p[0] = to_byte(p[0] / 255.0f * (1 - a) + c.r * a);
  p[1] = to_byte(p[1] / 255.0f * (1 - a) + c.g * a);
  p[2] = to_byte(p[2] / 255.0f * (1 - a) + c.b * a);
}

void Canvas::fill_rect(const Rect& r, Color c) {
  const Rect q = intersect(r, bounds());
  for (int y = q.y0; y < q.y1; ++y)
    for (int x = q.x0; x < q.x1; ++x) blend(x, y, c);
}

void Canvas::stroke_rect(const Rect& r, Color c, int width) {
  fill_rect({r.x0, r.y0, r.x1, r.y0 + width}, c);
  fill_rect({r.x0, r.y1 - width, r.x1, r.y1}, c);
  fill_rect({r.x0, r.y0 + width, r.x0 + width, r.y1 - width}, c);
  fill_rect({r.x1 - width, r.y0 + width, r.x1, r.y1 - width}, c);
}

void Canvas::hline(double y, double x0, double x1, const LineStyle& s) {
  if (x1 < x0) std::swap(x0, x1);
  const int wi = std::max(1, static_cast<int>(std::lround(s.width)));
  const int r0 = static_cast<int>(std::floor(y)) - (wi - 1) / 2;
  const int c0 = static_cast<int>(std::lround(x0)), c1 = static_cast<int>(std::lround(x1));
  for (int x = c0; x < c1; ++x) {
    if (!dash_on(s, x - c0)) continue;
    for (int k = 0; k < wi; ++k) blend(x, r0 + k, s.color);
  }
}

void Canvas::vline(double x, double y0, double y1, const LineStyle& s) {
  if (y1 < y0) std::swap(y0, y1);
  const int wi = std::max(1, static_cast<int>(std::lround(s.width)));
  const int c0 = static_cast<int>(std::floor(x)) - (wi - 1) / 2;
  const int r0 = static_cast<int>(std::lround(y0)), r1 = static_cast<int>(std::lround(y1));
  for (int y = r0; y < r1; ++y) {
    if (!dash_on(s, y - r0)) continue;
    for (int k = 0; k < wi; ++k) blend(c0 + k, y, s.color);
  }
}

void Canvas::line(double x0, double y0, double x1, double y1, const LineStyle& s, Rect clip) {
  line_impl(x0, y0, x1, y1, s, clip, 0);
}

// Pixels whose centre lies within width/2 (+ 0.5 px of anti-aliasing) of the segment, visited
// along the major axis so the cost is proportional to length x width.
void Canvas::line_impl(double x0, double y0, double x1, double y1, const LineStyle& s, Rect clip,
                       double dash_offset) {
  if (!std::isfinite(x0) || !std::isfinite(y0) || !std::isfinite(x1) || !std::isfinite(y1)) return;
  const Rect box = clip.empty() ? bounds() : intersect(clip, bounds());
  const double hw = std::max(s.width, 0.5) / 2;
  const double dx = x1 - x0, dy = y1 - y0;
  const double len2 = dx * dx + dy * dy, len = std::sqrt(len2);
  const bool steep = std::abs(dy) > std::abs(dx);
  // Work in (u, w) = (major, minor) coordinates.
  const double u0 = steep ? y0 : x0, u1 = steep ? y1 : x1;
  const double w0 = steep ? x0 : y0, w1 = steep ? x1 : y1;
  const double slope = (u1 != u0) ? (w1 - w0) / (u1 - u0) : 0;
  const double reach = hw * std::sqrt(1 + slope * slope) + 1;
  const int ua = static_cast<int>(std::floor(std::min(u0, u1) - hw - 1));
  const int ub = static_cast<int>(std::ceil(std::max(u0, u1) + hw + 1));
  for (int u = ua; u <= ub; ++u) {
    const double uc = u + 0.5;
    const double ucl = std::clamp(uc, std::min(u0, u1), std::max(u0, u1));
    const double wc = (u1 != u0) ? w0 + (ucl - u0) * slope : w0;
    const int wa = static_cast<int>(std::floor(wc - reach)),
              wb = static_cast<int>(std::ceil(wc + reach));
    for (int w = wa; w <= wb; ++w) {
      const int px = steep ? w : u, py = steep ? u : w;
      if (!box.contains(px, py)) continue;
      const double cx = px + 0.5 - x0, cy = py + 0.5 - y0;
      double t = len2 > 0 ? (cx * dx + cy * dy) / len2 : 0;
      t = std::clamp(t, 0.0, 1.0);
      const double ex = cx - t * dx, ey = cy - t * dy;
      const double d = std::sqrt(ex * ex + ey * ey);
      const double cov = std::clamp(hw + 0.5 - d, 0.0, 1.0);
      if (cov <= 0) continue;
      if (!dash_on(s, dash_offset + t * len)) continue;
      blend(px, py, s.color, static_cast<float>(cov));
    }
  }
}

void Canvas::polyline(std::span<const double> xs, std::span<const double> ys, const LineStyle& s,
                      Rect clip) {
  const size_t n = std::min(xs.size(), ys.size());
  double off = 0;
  for (size_t i = 1; i < n; ++i) {
    line_impl(xs[i - 1], ys[i - 1], xs[i], ys[i], s, clip, off);
    off += std::hypot(xs[i] - xs[i - 1], ys[i] - ys[i - 1]);
  }
}

void Canvas::series(const PlotArea& a, std::span<const double> x, std::span<const double> y,
                    const LineStyle& s) {
  envelope(a, column_ranges(a, x, y), s);
}

void Canvas::envelope(const PlotArea& a, const std::vector<ColumnRange>& cols, const LineStyle& s) {
  const double hw = std::max(s.width, 1.0) / 2;
  for (size_t i = 0; i < cols.size(); ++i) {
    const ColumnRange& cr = cols[i];
    if (!cr.valid) continue;
    const int x = a.rect.x0 + static_cast<int>(i);
    if (x >= a.rect.x1) break;
    double top = a.py(cr.hi) - hw, bot = a.py(cr.lo) + hw;
    top = std::max(top, static_cast<double>(a.rect.y0));
    bot = std::min(bot, static_cast<double>(a.rect.y1));
    for (int y = static_cast<int>(std::floor(top)); y < static_cast<int>(std::ceil(bot)); ++y) {
      const double cov = std::min(bot, y + 1.0) - std::max(top, static_cast<double>(y));
      if (cov > 0) blend(x, y, s.color, static_cast<float>(std::min(cov, 1.0)));
    }
  }
}

const std::string& Canvas::font(FontFace f) const {
  switch (f) {
    case FontFace::kBold:
      return fonts_.bold;
    case FontFace::kMono:
      return fonts_.mono;
    case FontFace::kSans:
      break;
  }
  return fonts_.sans;
}

Canvas::TextExtent Canvas::measure(std::string_view s, int size, FontFace face) const {
  const std::string a = ascii_text(s);
  TextExtent e;
  // Ascent / descent from reference glyphs so that labels of one size align alike.
  const Box ref = text_box("Hg", size, font(face));
  if (ref.defined) {
    e.ascent = -ref.ybegin;
    e.descent = ref.yend;
  }
  size_t lines = 1;
  int width = 0;
  size_t start = 0;
  while (true) {
    const size_t nl = a.find('\n', start);
    const std::string line =
        a.substr(start, nl == std::string::npos ? std::string::npos : nl - start);
    if (!line.empty()) {
      const Box r = text_box(line, size, font(face));
      if (r.defined) width = std::max(width, r.xend);
    }
    if (nl == std::string::npos) break;
    ++lines;
    start = nl + 1;
  }
  e.width = width;
  e.descent += static_cast<int>(lines - 1) * static_cast<int>(std::lround(size * 1.25));
  return e;
}

Rect Canvas::text(double x, double y, std::string_view s, int size, Color c, FontFace face,
                  HAlign ha, VAlign va, bool vertical) {
  const std::string a = ascii_text(s);
  if (a.find('\n') != std::string::npos) {  // one line at a time, 1.25 x size apart
    Rect all{};
    bool first = true;
    const TextExtent ext = measure(a, size, face);
    const double step = std::lround(size * 1.25);
    const size_t nlines = static_cast<size_t>(std::count(a.begin(), a.end(), '\n')) + 1;
    const double total = ext.ascent + ext.descent;  // first ascent to last descent
    double base = y;                                // baseline of the first line
    if (va == VAlign::kTop) base = y + ext.ascent;
    if (va == VAlign::kCenter) base = y - total / 2 + ext.ascent;
    if (va == VAlign::kBottom) base = y - total + ext.ascent;
    size_t start = 0;
    for (size_t i = 0; i < nlines; ++i) {
      const size_t nl = a.find('\n', start);
      const std::string line =
          a.substr(start, nl == std::string::npos ? std::string::npos : nl - start);
      const Rect r = text(x, base + step * static_cast<double>(i), line, size, c, face, ha,
                          VAlign::kBaseline, false);
      if (!r.empty()) {
        all = first ? r
                    : Rect{std::min(all.x0, r.x0), std::min(all.y0, r.y0), std::max(all.x1, r.x1),
                           std::max(all.y1, r.y1)};
        first = false;
      }
      start = nl + 1;
    }
    return all;
  }
  if (a.empty()) return {};
  const std::string& fontfile = font(face);
  const Box r = text_box(a, size, fontfile);
  if (!r.defined) return {};
  const Box ref = text_box("Hg", size, fontfile);
  const int ascent = ref.defined ? -ref.ybegin : size;
  const int descent = ref.defined ? ref.yend : 0;
  // Mask box in baseline coordinates: x in [0, xend), y in [-ascent', descent').
  const int top = std::min(r.ybegin, -ascent), bottom = std::max(r.yend, descent);
  const int pad = 2;
  const int mw = std::max(r.xend, 1) + 2 * pad, mh = bottom - top + 2 * pad;
  std::vector<float> mask(static_cast<size_t>(mw) * static_cast<size_t>(mh), 0.0f);
  if (!image_plugin().api->render_text(mask.data(), mw, mh, pad, pad - top, a.c_str(), size,
                                       fontfile.c_str()))
    return {};
  const float* m = mask.data();
  // Where the mask's (0, 0) goes, for the box the alignment refers to.
  int ox = 0, oy = 0;
  if (!vertical) {
    const int width = r.xend;
    double bx = x;  // baseline origin
    if (ha == HAlign::kCenter) bx = x - width / 2.0;
    if (ha == HAlign::kRight) bx = x - width;
    double by = y;
    if (va == VAlign::kTop) by = y + ascent;
    if (va == VAlign::kCenter) by = y + (ascent - descent) / 2.0;
    if (va == VAlign::kBottom) by = y - descent;
    ox = static_cast<int>(std::lround(bx)) - pad;
    oy = static_cast<int>(std::lround(by)) + top - pad;
    for (int my = 0; my < mh; ++my)
      for (int mx = 0; mx < mw; ++mx) {
        const float cov = m[static_cast<size_t>(my) * mw + mx];
        if (cov > 0) blend(ox + mx, oy + my, c, std::min(cov, 1.0f));
      }
    return {ox + pad, static_cast<int>(std::lround(by)) - ascent, ox + pad + width,
            static_cast<int>(std::lround(by)) + descent};
  }
  // Rotated a quarter turn counter-clockwise: mask (mx, my) -> (my, mw - 1 - mx).
  const int rw = mh, rh = mw;
  double bx = x, by = y;
  if (ha == HAlign::kCenter) bx = x - rw / 2.0;
  if (ha == HAlign::kRight) bx = x - rw;
  if (va == VAlign::kCenter) by = y - rh / 2.0;
  if (va == VAlign::kBottom || va == VAlign::kBaseline) by = y - rh;
  ox = static_cast<int>(std::lround(bx));
  oy = static_cast<int>(std::lround(by));
  for (int my = 0; my < mh; ++my)
    for (int mx = 0; mx < mw; ++mx) {
      const float cov = m[static_cast<size_t>(my) * mw + mx];
      if (cov > 0) blend(ox + my, oy + (mw - 1 - mx), c, std::min(cov, 1.0f));
    }
  return {ox, oy, ox + rw, oy + rh};
}

Status Canvas::write_png(const std::string& path) const {
  // OpenImageIO reports success when the disk fills up under it, so the plug-in encodes the PNG
  // into memory and base/file_io.h does the checked, atomic write.
  std::vector<unsigned char> bytes;
  char err[512] = "";
  auto sink = [](void* ctx, const unsigned char* data, size_t n) {
    static_cast<std::vector<unsigned char>*>(ctx)->assign(data, data + n);
  };
  if (image_plugin().api->encode_png(w_, h_, px_.data(), sink, &bytes, err, sizeof err) != 0) {
    return Status::Error(fmt::format("{}: error: cannot encode the PNG: {}", path, err));
  }
  return write_file_atomic(
      path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

Rect draw_runs(Canvas& c, double x, double y, const std::vector<TextRun>& runs, int size,
               VAlign va) {
  Rect all{};
  bool first = true;
  double cx = x;
  for (const TextRun& r : runs) {
    if (r.text.empty()) continue;
    const Rect b = c.text(cx, y, r.text, size, r.color, r.face, HAlign::kLeft, va);
    cx += c.measure(r.text, size, r.face).width;
    if (b.empty()) continue;
    all = first ? b
                : Rect{std::min(all.x0, b.x0), std::min(all.y0, b.y0), std::max(all.x1, b.x1),
                       std::max(all.y1, b.y1)};
    first = false;
  }
  return all;
}

Rect draw_label(Canvas& c, double x, double y, std::string_view s, int size, Color text, HAlign ha,
                VAlign va, Color background, int pad, FontFace face) {
  const Canvas::TextExtent e = c.measure(s, size, face);
  double left = x;
  if (ha == HAlign::kCenter) left = x - e.width / 2.0;
  if (ha == HAlign::kRight) left = x - e.width;
  double base = y;
  if (va == VAlign::kTop) base = y + e.ascent;
  if (va == VAlign::kCenter) base = y + (e.ascent - e.descent) / 2.0;
  if (va == VAlign::kBottom) base = y - e.descent;
  const Rect box{static_cast<int>(std::floor(left)) - pad,
                 static_cast<int>(std::floor(base)) - e.ascent - pad,
                 static_cast<int>(std::ceil(left)) + e.width + pad,
                 static_cast<int>(std::ceil(base)) + e.descent + pad};
  c.fill_rect(box, background);
  c.text(left, base, s, size, text, face, HAlign::kLeft, VAlign::kBaseline);
  return box;
}

std::vector<double> spread_labels(const std::vector<double>& wanted, double min_gap, double lo,
                                  double hi) {
  const size_t n = wanted.size();
  std::vector<size_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return wanted[a] < wanted[b]; });
  // Clusters of labels packed min_gap apart, each centred on the mean of what its labels want.
  struct Cluster {
    size_t first, count;
    double sum;  // sum of (wanted - k * gap) over its labels
    double start() const { return sum / static_cast<double>(count); }
  };
  std::vector<Cluster> cl;
  for (size_t k = 0; k < n; ++k) {
    cl.push_back({k, 1, wanted[order[k]]});
    while (cl.size() > 1) {
      Cluster& a = cl[cl.size() - 2];
      const Cluster& b = cl.back();
      if (a.start() + static_cast<double>(a.count) * min_gap <= b.start()) break;
      double add = 0;
      for (size_t j = 0; j < b.count; ++j)
        add += wanted[order[b.first + j]] - static_cast<double>(a.count + j) * min_gap;
      a.sum += add;
      a.count += b.count;
      cl.pop_back();
    }
  }
  std::vector<double> out(n);
  for (const Cluster& c : cl) {
    double s = c.start();
    const double span = static_cast<double>(c.count - 1) * min_gap;
    if (s + span > hi) s = hi - span;
    if (s < lo) s = lo;
    for (size_t j = 0; j < c.count; ++j)
      out[order[c.first + j]] = s + static_cast<double>(j) * min_gap;
  }
  // Clamping may have pushed neighbouring clusters together: one forward pass keeps the gap.
  for (size_t k = 1; k < n; ++k)
    out[order[k]] = std::max(out[order[k]], out[order[k - 1]] + min_gap);
  return out;
}

// --- ticks ---------------------------------------------------------------------------------------

UnitScale si_scale(double max_abs, std::string_view base_unit) {
  static const std::pair<int, const char*> kPrefix[] = {{-12, "p"}, {-9, "n"}, {-6, "u"}, {-3, "m"},
                                                        {0, ""},    {3, "k"},  {6, "M"},  {9, "G"}};
  UnitScale u{1, std::string(base_unit)};
  if (!(max_abs > 0) || !std::isfinite(max_abs)) return u;
  const int e = static_cast<int>(std::floor(std::log10(max_abs) + 1e-9));
  int p = 3 * static_cast<int>(std::floor(e / 3.0));
  p = std::clamp(p, -12, 9);
  for (const auto& [exp, name] : kPrefix)
    if (exp == p) {
      u.factor = std::pow(10.0, -p);
      u.unit = std::string(name) + std::string(base_unit);
    }
  return u;
}

double nice_step(double span, int target) {
  if (!(span > 0) || target < 1) return 1;
  const double raw = span / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * mag >= raw * (1 - 1e-9)) return m * mag;
  return 10 * mag;
}

std::vector<double> tick_values(double lo, double hi, double step) {
  std::vector<double> out;
  if (!(step > 0) || !(hi > lo)) return out;
  const double eps = step * 1e-6;
  const double first = std::ceil((lo - eps) / step);
  for (double k = first;; k += 1) {
    const double v = k * step;
    if (v > hi + eps) break;
    out.push_back(std::abs(v) < eps ? 0.0 : v);
    if (out.size() > 1000) break;
  }
  return out;
}

std::string tick_label(double value, double step, const UnitScale& u) {
  const double s = std::abs(step * u.factor);
  int dec = 0;
  while (dec < 6) {
    const double scaled = s * std::pow(10.0, dec);
    if (std::abs(scaled - std::round(scaled)) < 1e-6 * std::max(1.0, scaled)) break;
    ++dec;
  }
  double v = value * u.factor;
  if (std::abs(v) < s * 1e-6) v = 0;
  return fmt::format("{:.{}f}", v, dec);
}

AxisTicks make_ticks(const Axis& a, const UnitScale& u, int target) {
  const double lo = std::min(a.lo, a.hi), hi = std::max(a.lo, a.hi);
  const double step = nice_step(hi - lo, target);
  return ticks_at(tick_values(lo, hi, step), step, u);
}

std::string si_label(double v) {
  std::string s = link::format_si(v, "");
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

AxisTicks decade_ticks(double lo, double hi, const std::string& unit,
                       const std::function<std::string(double)>& label) {
  AxisTicks t;
  t.unit = UnitScale{1, unit};
  t.step = 1;
  for (int k = static_cast<int>(std::ceil(lo - 1e-9)); k <= static_cast<int>(std::floor(hi + 1e-9));
       ++k)
    t.ticks.push_back({static_cast<double>(k), label(std::pow(10.0, k))});
  return t;
}

AxisTicks ticks_at(std::vector<double> values, double step, const UnitScale& u) {
  AxisTicks t;
  t.unit = u;
  t.step = step;
  for (double v : values) t.ticks.push_back({v, tick_label(v, step, u)});
  return t;
}

void draw_grid(Canvas& c, const PlotArea& a, const AxisTicks& xt, const AxisTicks& yt,
               Color color) {
  const LineStyle g{.color = color, .width = 1};
  for (const Tick& t : xt.ticks) {
    const int x = a.col(t.value);
    if (x > a.rect.x0 && x < a.rect.x1 - 1) c.vline(x, a.rect.y0, a.rect.y1, g);
  }
  for (const Tick& t : yt.ticks) {
    const int y = a.row(t.value);
    if (y > a.rect.y0 && y < a.rect.y1 - 1) c.hline(y, a.rect.x0, a.rect.x1, g);
  }
}

void draw_axes(Canvas& c, const PlotArea& a, const AxisTicks& xt, const AxisTicks& yt,
               const std::string& x_title, const std::string& y_title, int font_size) {
  const Rect& r = a.rect;
  c.stroke_rect({r.x0 - 1, r.y0 - 1, r.x1 + 1, r.y1 + 1}, kInk, 1);
  const LineStyle tick{.color = kInk, .width = 1};
  const int tl = 7;
  for (const Tick& t : xt.ticks) {
    const int x = std::clamp(a.col(t.value), r.x0, r.x1 - 1);
    c.vline(x, r.y1 + 1, r.y1 + 1 + tl, tick);
    c.text(x + 0.5, r.y1 + tl + 5, t.label, font_size, kInk, FontFace::kSans, HAlign::kCenter,
           VAlign::kTop);
  }
  int label_w = 0;
  for (const Tick& t : yt.ticks) {
    const int y = std::clamp(a.row(t.value), r.y0, r.y1 - 1);
    c.hline(y, r.x0 - 1 - tl, r.x0 - 1, tick);
    const Rect b = c.text(r.x0 - tl - 6, y + 0.5, t.label, font_size, kInk, FontFace::kSans,
                          HAlign::kRight, VAlign::kCenter);
    label_w = std::max(label_w, b.width());
  }
  auto titled = [](const std::string& title, const UnitScale& u) {
    return u.unit.empty() ? title : title + " [" + u.unit + "]";
  };
  const int title_size = font_size + 2;
  if (!x_title.empty())
    c.text((r.x0 + r.x1) / 2.0, r.y1 + tl + 10 + font_size * 1.3, titled(x_title, xt.unit),
           title_size, kInk, FontFace::kSans, HAlign::kCenter, VAlign::kTop);
  if (!y_title.empty())
    c.text(r.x0 - tl - 14 - label_w, (r.y0 + r.y1) / 2.0, titled(y_title, yt.unit), title_size,
           kInk, FontFace::kSans, HAlign::kRight, VAlign::kCenter, /*vertical=*/true);
}

// --- legend --------------------------------------------------------------------------------------

namespace {
constexpr int kLegendPad = 10, kLegendSample = 40, kLegendGap = 10;
}

Rect legend_size(const Canvas& c, const std::vector<LegendEntry>& entries, int font_size) {
  int w = 0;
  for (const LegendEntry& e : entries) w = std::max(w, c.measure(e.label, font_size).width);
  const int row = static_cast<int>(std::lround(font_size * 1.45));
  return {0, 0, 2 * kLegendPad + kLegendSample + kLegendGap + w,
          2 * kLegendPad + row * static_cast<int>(entries.size()) - (row - font_size) / 2};
}

Rect draw_legend(Canvas& c, int x, int y, const std::vector<LegendEntry>& entries, int font_size) {
  const Rect sz = legend_size(c, entries, font_size);
  const Rect box{x, y, x + sz.width(), y + sz.height()};
  c.fill_rect(box, kWhite.with_alpha(0.92f));
  c.stroke_rect(box, rgb(0x999999), 1);
  const int row = static_cast<int>(std::lround(font_size * 1.45));
  for (size_t i = 0; i < entries.size(); ++i) {
    const LegendEntry& e = entries[i];
    const double cy = y + kLegendPad + row * static_cast<double>(i) + font_size * 0.6;
    const int sx = x + kLegendPad;
    if (e.box) {
      const Rect sw{sx, static_cast<int>(cy - font_size * 0.4), sx + kLegendSample,
                    static_cast<int>(cy + font_size * 0.4)};
      c.fill_rect(sw, e.line.color);
      // Outline in a darker shade of the swatch, so light tints stay visible.
      const Color k = e.line.color;
      c.stroke_rect(sw, Color{k.r * 0.6f, k.g * 0.6f, k.b * 0.6f, std::max(k.a, 0.5f)}, 1);
    } else {
      LineStyle s = e.line;
      s.width = std::max(s.width, 2.0);
      c.hline(std::floor(cy), sx, sx + kLegendSample, s);
    }
    c.text(sx + kLegendSample + kLegendGap, cy, e.label, font_size, kInk, FontFace::kSans,
           HAlign::kLeft, VAlign::kCenter);
  }
  return box;
}

// --- colour maps ---------------------------------------------------------------------------------

namespace {

// Degree-6 polynomial fits (by Matt Zucker, CC0) of matplotlib's viridis and inferno, which are
// CC0 as well; within about 0.01 of the published tables per channel.
using Poly = std::array<std::array<double, 3>, 7>;
constexpr Poly kViridis = {{{0.2777273272234177, 0.005407344544966578, 0.3340998053353061},
                            {0.1050930431085774, 1.404613529898575, 1.384590162594685},
                            {-0.3308618287255563, 0.214847559468213, 0.09509516302823659},
                            {-4.634230498983486, -5.799100973351585, -19.33244095627987},
                            {6.228269936347081, 14.17993336680509, 56.69055260068105},
                            {4.776384997670288, -13.74514537774601, -65.35303263337234},
                            {-5.435455855934631, 4.645852612178535, 26.3124352495832}}};
constexpr Poly kInferno = {{{0.0002189403691192265, 0.001651004631001012, -0.01948089843709184},
                            {0.1065134194856116, 0.5639564367884091, 3.932712388889277},
                            {11.60249308247187, -3.972853965665698, -15.9423941062914},
                            {-41.70399613139459, 17.43639888205313, 44.35414519872813},
                            {77.162935699427, -33.40235894210092, -81.80730925738993},
                            {-71.31942824499214, 32.62606426397723, 73.20951985803202},
                            {25.13112622477341, -12.24266895238567, -23.07032500287172}}};

std::array<Color, 256> table_of(const Poly& p) {
  std::array<Color, 256> t{};
  for (int i = 0; i < 256; ++i) {
    const double x = i / 255.0;
    double ch[3];
    for (int k = 0; k < 3; ++k) {
      double acc = 0;
      for (int d = 6; d >= 0; --d) acc = acc * x + p[d][k];
      ch[k] = std::clamp(acc, 0.0, 1.0);
    }
    t[i] = Color{static_cast<float>(ch[0]), static_cast<float>(ch[1]), static_cast<float>(ch[2])};
  }
  return t;
}

}  // namespace

const ColorMap& ColorMap::viridis() {
  static const ColorMap m(table_of(kViridis));
  return m;
}

const ColorMap& ColorMap::inferno() {
  static const ColorMap m(table_of(kInferno));
  return m;
}

Color ColorMap::at(double t) const {
  if (!(t >= 0)) t = 0;
  const int i = static_cast<int>(std::lround(std::min(t, 1.0) * 255));
  return table_[static_cast<size_t>(i)];
}

double LogScale::norm(double count) const {
  if (!(max > 1)) return 1.0;
  if (!(count > 1)) return 0.0;
  return std::min(1.0, std::log(count) / std::log(max));
}

void draw_colorbar(Canvas& c, const Rect& r, const ColorMap& map, const LogScale& scale,
                   const std::string& title, int font_size) {
  const bool vertical = r.height() > r.width();
  const int len = vertical ? r.height() : r.width();
  for (int k = 0; k < len; ++k) {
    const double t = len > 1 ? static_cast<double>(k) / (len - 1) : 1.0;
    if (vertical)
      c.fill_rect({r.x0, r.y1 - 1 - k, r.x1, r.y1 - k}, map.at(t));
    else
      c.fill_rect({r.x0 + k, r.y0, r.x0 + k + 1, r.y1}, map.at(t));
  }
  c.stroke_rect({r.x0 - 1, r.y0 - 1, r.x1 + 1, r.y1 + 1}, kInk, 1);
  auto label = [](double v) {
    if (v >= 1e6) return fmt::format("{:g}M", v / 1e6);
    if (v >= 1e3) return fmt::format("{:g}k", v / 1e3);
    return fmt::format("{:g}", v);
  };
  // Position along the bar (px from its low end) of a count.
  auto pos = [&](double count) { return scale.norm(count) * (len - 1); };
  const LineStyle tick{.color = kInk, .width = 1};
  auto mark = [&](double count) {
    const double p = pos(count);
    if (vertical) {
      const double y = r.y1 - 1 - p;
      c.hline(std::floor(y), r.x1, r.x1 + 6, tick);
      c.text(r.x1 + 10, y + 0.5, label(count), font_size, kInk, FontFace::kSans, HAlign::kLeft,
             VAlign::kCenter);
    } else {
      const double x = r.x0 + p;
      c.vline(std::floor(x), r.y1, r.y1 + 6, tick);
      c.text(x + 0.5, r.y1 + 8, label(count), font_size, kInk, FontFace::kSans, HAlign::kCenter,
             VAlign::kTop);
    }
  };
  const double max = std::max(scale.max, 1.0);
  double last = 0;
  for (double d = 1; d <= max * 1.0001; d *= 10) {
    mark(d);
    last = pos(d);
  }
  if (max > 1 && pos(max) - last > font_size * 2.2) mark(std::round(max));  // the top, when room
  if (!title.empty()) {
    if (vertical)
      c.text((r.x0 + r.x1) / 2.0, r.y0 - 12, title, font_size, kInk, FontFace::kSans,
             HAlign::kCenter, VAlign::kBottom);
    else
      c.text(r.x0, r.y0 - 8, title, font_size, kInk, FontFace::kSans, HAlign::kLeft,
             VAlign::kBottom);
  }
}

void fill_cells(Canvas& c, const PlotArea& a, int nx, int ny,
                const std::function<std::optional<Color>(int ix, int iy)>& cell) {
  if (nx <= 0 || ny <= 0) return;
  for (int y = a.rect.y0; y < a.rect.y1; ++y) {
    const double fy = (a.y.from_px(y + 0.5) - a.y.lo) / (a.y.hi - a.y.lo);
    const int iy = static_cast<int>(std::floor(fy * ny));
    if (iy < 0 || iy >= ny) continue;
    for (int x = a.rect.x0; x < a.rect.x1; ++x) {
      const double fx = (a.x.from_px(x + 0.5) - a.x.lo) / (a.x.hi - a.x.lo);
      const int ix = static_cast<int>(std::floor(fx * nx));
      if (ix < 0 || ix >= nx) continue;
      if (std::optional<Color> col = cell(ix, iy)) c.blend(x, y, *col);
    }
  }
}

std::vector<ColumnRange> column_ranges(const PlotArea& a, std::span<const double> x,
                                       std::span<const double> y) {
  const int ncol = a.rect.width();
  std::vector<ColumnRange> out(static_cast<size_t>(std::max(ncol, 0)));
  const size_t n = std::min(x.size(), y.size());
  if (n == 0 || ncol <= 0) return out;
  const double xfirst = x[0], xlast = x[n - 1];
  auto interp = [&](double xv, size_t hi) {  // x[hi - 1] <= xv <= x[hi]
    if (hi == 0) return y[0];
    if (hi >= n) return y[n - 1];
    const double xa = x[hi - 1], xb = x[hi];
    return xb == xa ? y[hi] : y[hi - 1] + (xv - xa) / (xb - xa) * (y[hi] - y[hi - 1]);
  };
  size_t i = 0;  // first sample with x[i] > the current column's left edge
  for (int col = 0; col < ncol; ++col) {
    double l = a.x.from_px(a.rect.x0 + col), r = a.x.from_px(a.rect.x0 + col + 1);
    if (l > r) std::swap(l, r);
    if (r < xfirst || l > xlast) continue;
    l = std::max(l, xfirst);
    r = std::min(r, xlast);
    while (i < n && x[i] <= l) ++i;
    ColumnRange cr;
    cr.valid = true;
    cr.lo = cr.hi = interp(l, i);
    size_t k = i;
    while (k < n && x[k] <= r) {
      cr.lo = std::min(cr.lo, y[k]);
      cr.hi = std::max(cr.hi, y[k]);
      ++k;
    }
    const double yr = interp(r, k);
    cr.lo = std::min(cr.lo, yr);
    cr.hi = std::max(cr.hi, yr);
    out[static_cast<size_t>(col)] = cr;
  }
  return out;
}

std::vector<ColumnRange> mean_column_ranges(const PlotArea& a, std::span<const double> x,
                                            std::span<const double> y1,
                                            std::span<const double> y2) {
  constexpr size_t kBlock = 1 << 16;
  const size_t n = std::min({x.size(), y1.size(), y2.size()});
  std::vector<ColumnRange> all(static_cast<size_t>(std::max(a.rect.width(), 0)));
  std::vector<double> mean;
  for (size_t i0 = 0; i0 < n; i0 += kBlock) {
    const size_t i1 = std::min(n, i0 + kBlock + 1);  // + 1: the next block's first sample
    mean.resize(i1 - i0);
    for (size_t i = i0; i < i1; ++i) mean[i - i0] = 0.5 * (y1[i] + y2[i]);
    const std::vector<ColumnRange> block = column_ranges(a, x.subspan(i0, i1 - i0), mean);
    for (size_t k = 0; k < block.size() && k < all.size(); ++k) {
      if (!block[k].valid) continue;
      ColumnRange& r = all[k];
      r.lo = r.valid ? std::min(r.lo, block[k].lo) : block[k].lo;
      r.hi = r.valid ? std::max(r.hi, block[k].hi) : block[k].hi;
      r.valid = true;
    }
    if (i1 == n) break;
  }
  return all;
}

}  // namespace isolink::reports

namespace isolink::reports {

std::vector<ContourSegment> contour_segments(const PlotArea& a, std::span<const double> z, int nx,
                                             int ny, double level) {
  std::vector<ContourSegment> out;
  if (nx < 2 || ny < 2 || z.size() < static_cast<size_t>(nx) * static_cast<size_t>(ny)) return out;
  const double dx = (a.x.hi - a.x.lo) / nx, dy = (a.y.hi - a.y.lo) / ny;
  auto X = [&](double i) { return a.x.lo + (i + 0.5) * dx; };  // cell centre of column i
  auto Y = [&](double j) { return a.y.lo + (j + 0.5) * dy; };
  auto Z = [&](int i, int j) { return z[static_cast<size_t>(j) * nx + i] - level; };
  struct P {
    double x, y;
  };
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      // Corners counter-clockwise from the lower left, and the crossings on the four edges.
      const double z0 = Z(i, j), z1 = Z(i + 1, j), z2 = Z(i + 1, j + 1), z3 = Z(i, j + 1);
      if (std::isnan(z0) || std::isnan(z1) || std::isnan(z2) || std::isnan(z3)) continue;
      const int code = (z0 > 0) | (z1 > 0) << 1 | (z2 > 0) << 2 | (z3 > 0) << 3;
      if (code == 0 || code == 15) continue;
      auto cross = [](double za, double zb) { return za / (za - zb); };
      const P bottom{X(i + cross(z0, z1)), Y(j)}, right{X(i + 1), Y(j + cross(z1, z2))};
      const P top{X(i + cross(z3, z2)), Y(j + 1)}, left{X(i), Y(j + cross(z0, z3))};
      auto seg = [&](P p, P q) { out.push_back({p.x, p.y, q.x, q.y}); };
      const bool centre_up = (z0 + z1 + z2 + z3) > 0;  // resolves the saddles
      switch (code) {
        case 1:
        case 14:
          seg(left, bottom);
          break;
        case 2:
        case 13:
          seg(bottom, right);
          break;
        case 3:
        case 12:
          seg(left, right);
          break;
        case 4:
        case 11:
          seg(right, top);
          break;
        case 6:
        case 9:
          seg(bottom, top);
          break;
        case 7:
        case 8:
          seg(left, top);
          break;
        case 5:
          if (centre_up) {
            seg(left, top);
            seg(bottom, right);
          } else {
            seg(left, bottom);
            seg(right, top);
          }
          break;
        case 10:
          if (centre_up) {
            seg(left, bottom);
            seg(right, top);
          } else {
            seg(left, top);
            seg(bottom, right);
          }
          break;
        default:
          break;
      }
    }
  return out;
}

void draw_contour(Canvas& c, const PlotArea& a, const std::vector<ContourSegment>& segs,
                  const LineStyle& s) {
  for (const ContourSegment& g : segs)
    c.line(a.px(g.x0), a.py(g.y0), a.px(g.x1), a.py(g.y1), s, a.rect);
}

}  // namespace isolink::reports
