#include "eye/scope_binary.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string_view>

#include "eye/scope_formats.h"

namespace isolink::eye {
namespace {

struct Closer {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, Closer>;

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string ext_of(const std::string& path) {
  const size_t dot = path.rfind('.');
  const size_t slash = path.find_last_of("/\\");
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  return lower(path.substr(dot + 1));
}

// ---- the shared byte cursor ----

// A block of a binary file read in one byte order; offsets are relative to the block and
// at(off) gives the file offset for messages. Readers load the whole fixed-size header they
// decode, so every field lies inside the block (a field past its end reads as 0).
struct Fields {
  std::vector<unsigned char> b;
  uint64_t base = 0;  // file offset of b[0]
  bool big = false;   // big-endian (most significant byte first)

  uint64_t at(size_t off) const { return base + off; }
  uint64_t u(size_t off, size_t width) const {
    if (off + width > b.size()) return 0;
    uint64_t x = 0;
    for (size_t k = 0; k < width; ++k)
      x |= static_cast<uint64_t>(b[off + k]) << (8 * (big ? width - 1 - k : k));
    return x;
  }
  int64_t s(size_t off, size_t width) const {
    const uint64_t x = u(off, width);
    if (width >= 8) return static_cast<int64_t>(x);
    const uint64_t sign = uint64_t{1} << (8 * width - 1);
    return static_cast<int64_t>(x ^ sign) - static_cast<int64_t>(sign);
  }
  double f32(size_t off) const {
    const auto bits = static_cast<uint32_t>(u(off, 4));
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
  }
  double f64(size_t off) const {
    const uint64_t bits = u(off, 8);
    double d;
    std::memcpy(&d, &bits, 8);
    return d;
  }
  // Text up to the first NUL, blanks trimmed at both ends.
  std::string text(size_t off, size_t n) const {
    std::string out;
    for (size_t k = off; k < std::min(b.size(), off + n) && b[k] != 0; ++k)
      out += static_cast<char>(b[k]);
    while (!out.empty() && std::isspace(static_cast<unsigned char>(out.back()))) out.pop_back();
    const size_t first = out.find_first_not_of(" \t\r\n");
    return first == std::string::npos ? "" : out.substr(first);
  }
};

enum class Sample { kI8, kU8, kI16, kU16, kI32, kU32, kF32, kF64 };

size_t width_of(Sample k) {
  switch (k) {
    case Sample::kI8:
    case Sample::kU8:
      return 1;
    case Sample::kI16:
    case Sample::kU16:
      return 2;
    case Sample::kI32:
    case Sample::kU32:
    case Sample::kF32:
      return 4;
    case Sample::kF64:
      return 8;
  }
  return 1;
}

// A binary capture opened for reading. Its length is known up front; every range is checked
// against it before it is read or anything is reserved for it, and errors name the byte offset.
class BinFile {
 public:
  static StatusOr<BinFile> open(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
      return Status::Error(path + ": error: a folder, not a capture file");
    File f(std::fopen(path.c_str(), "rb"));
    if (!f) return Status::Error(fmt::format("{}: error: cannot open: {}", path, strerror(errno)));
    if (fseeko(f.get(), 0, SEEK_END) != 0)
      return Status::Error(path + ": error: cannot seek: not a regular file");
    const off_t n = ftello(f.get());
    if (n < 0) return Status::Error(path + ": error: cannot tell the file's length");
    BinFile out;
    out.path_ = path;
    out.size_ = static_cast<uint64_t>(n);
    out.f_ = std::move(f);
    return out;
  }
  const std::string& path() const { return path_; }
  uint64_t size() const { return size_; }

  Status error(uint64_t at, std::string_view why) const {
    return Status::Error(fmt::format("{}:byte {}: error: {}", path_, at, why));
  }
  // Refuses [at, at + n) when it runs past the end of the file; `what` names the block.
  Status need(uint64_t at, uint64_t n, std::string_view what) const {
    if (at > size_ || n > size_ - at)
      return error(at, fmt::format("{} needs {} bytes from byte {}, but the file ends at byte {}: "
                                   "the file is cut short or the header is wrong",
                                   what, n, at, size_));
    return Status::Ok();
  }
  StatusOr<Fields> fields(uint64_t at, uint64_t n, bool big, std::string_view what) {
    if (Status st = need(at, n, what); !st.ok()) return st;
    Fields out;
    out.base = at;
    out.big = big;
    out.b.resize(n);
    if (fseeko(f_.get(), static_cast<off_t>(at), SEEK_SET) != 0 ||
        std::fread(out.b.data(), 1, n, f_.get()) != n)
      return error(at, fmt::format("cannot read {}", what));
    return out;
  }
  // Appends n samples read from `at` to *v as gain * raw + offset, in chunks; the range is
  // checked first, so what is reserved is what the file holds.
  Status samples(uint64_t at, uint64_t n, Sample kind, bool big, double gain, double offset,
                 std::vector<double>* v, std::string_view what) {
    const size_t w = width_of(kind);
    if (n > (uint64_t{1} << 56) / w)  // no header count is this large
      return error(at, fmt::format("{} claims {} samples", what, n));
    if (Status st = need(at, n * w, what); !st.ok()) return st;
    if (fseeko(f_.get(), static_cast<off_t>(at), SEEK_SET) != 0)
      return error(at, fmt::format("cannot seek to {}", what));
    v->reserve(v->size() + n);
    Fields chunk;
    chunk.big = big;
    constexpr uint64_t kChunk = 1 << 16;
    for (uint64_t i = 0; i < n;) {
      const uint64_t m = std::min(kChunk, n - i);
      chunk.b.resize(m * w);
      if (std::fread(chunk.b.data(), w, m, f_.get()) != m)
        return error(at + i * w, fmt::format("cannot read {}", what));
      // one decoding loop per sample type; bytes swapped when the file's order is not the host's
      const bool swap = big != (std::endian::native == std::endian::big);
      uint64_t bad = m;
      double bad_x = 0;
      auto run = [&]<class T>() {
        const unsigned char* p = chunk.b.data();
        for (uint64_t k = 0; k < m; ++k, p += sizeof(T)) {
          unsigned char b[sizeof(T)];
          std::memcpy(b, p, sizeof(T));
          if (swap) std::reverse(b, b + sizeof(T));
          T raw;
          std::memcpy(&raw, b, sizeof(T));
          const double x = gain * static_cast<double>(raw) + offset;
          if (!std::isfinite(x) || std::abs(x) > 1e30) {
            bad = k;
            bad_x = x;
            return;
          }
          v->push_back(x);
        }
      };
      switch (kind) {
        case Sample::kI8:
          run.template operator()<int8_t>();
          break;
        case Sample::kU8:
          run.template operator()<uint8_t>();
          break;
        case Sample::kI16:
          run.template operator()<int16_t>();
          break;
        case Sample::kU16:
          run.template operator()<uint16_t>();
          break;
        case Sample::kI32:
          run.template operator()<int32_t>();
          break;
        case Sample::kU32:
          run.template operator()<uint32_t>();
          break;
        case Sample::kF32:
          run.template operator()<float>();
          break;
        case Sample::kF64:
          run.template operator()<double>();
          break;
      }
      if (bad < m)
        return error(at + (i + bad) * w, fmt::format("{}: sample {} is {:g}: a clipped or invalid "
                                                     "sample",
                                                     what, i + bad, bad_x));
      i += m;
    }
    return Status::Ok();
  }

 private:
  BinFile() = default;
  std::string path_;
  uint64_t size_ = 0;
  File f_;
};

// t = t0 + i * dt for every sample of tr.v.
void uniform_time(BinaryTrace* tr, double t0, double dt) {
  tr->t.clear();
  tr->t.reserve(tr->v.size());
  for (size_t i = 0; i < tr->v.size(); ++i) tr->t.push_back(t0 + static_cast<double>(i) * dt);
}

// A reader's result of one trace, moved in (a braced list would copy the samples).
std::vector<BinaryTrace> one_trace(BinaryTrace&& tr) {
  std::vector<BinaryTrace> out;
  out.push_back(std::move(tr));
  return out;
}

// A unit written in a header, as a scale to volts (or seconds); nullopt when it is neither.
std::optional<double> scale_to(const std::string& unit, UnitKind kind) {
  std::optional<Unit> u = parse_unit(unit);
  if (!u || u->kind != kind) return std::nullopt;
  return u->scale;
}

// ---- Tektronix .isf ----

// Tektronix preamble: "KEY value" pairs separated by ';', keys with or without a ":WFMPRE:"
// / ":WFMOUTPRE:" prefix, long or short forms.
struct IsfHeader {
  std::vector<std::pair<std::string, std::string>> kv;
  const std::string* get(std::initializer_list<const char*> keys) const {
    for (const char* k : keys)
      for (const auto& [key, value] : kv)
        if (key == k) return &value;
    return nullptr;
  }
};

bool to_double(const std::string* s, double* x) {
  if (!s) return false;
  const char* b = s->data();
  while (b < s->data() + s->size() && *b == '+') ++b;
  auto [p, ec] = std::from_chars(b, s->data() + s->size(), *x);
  return ec == std::errc() && p == s->data() + s->size() && std::isfinite(*x);
}

StatusOr<std::vector<BinaryTrace>> read_isf(BinFile& f) {
  StatusOr<Fields> block = f.fields(0, std::min<uint64_t>(f.size(), 4096), false, "the preamble");
  if (!block) return block.status();
  const std::string head(block->b.begin(), block->b.end());
  const size_t curve = head.find(":CURV");
  if (curve == std::string::npos)
    return f.error(0,
                   "no ':CURVE #' block in the first 4096 bytes: expected a Tektronix .isf file "
                   "(WFMOutpre preamble, then :CURVE #<n><length><data>)");
  IsfHeader h;
  std::string pre = head.substr(0, curve);
  size_t s = 0;
  while (s < pre.size()) {
    size_t e = s;
    bool quoted = false;
    while (e < pre.size() && (quoted || pre[e] != ';')) {
      if (pre[e] == '"') quoted = !quoted;
      ++e;
    }
    std::string item = pre.substr(s, e - s);
    s = e + 1;
    while (!item.empty() && (item[0] == ':' || std::isspace(static_cast<unsigned char>(item[0]))))
      item.erase(0, 1);
    for (const char* pfx : {"WFMPRE:", "WFMPre:", "WFMOUTPRE:", "WFMOutpre:", "WFMO:"})
      if (item.rfind(pfx, 0) == 0) item.erase(0, std::strlen(pfx));
    const size_t sp = item.find(' ');
    if (sp == std::string::npos) continue;
    std::string key = item.substr(0, sp), value = item.substr(sp + 1);
    for (char& c : key) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    while (!value.empty() && std::isspace(static_cast<unsigned char>(value.back())))
      value.pop_back();
    if (value.size() >= 2 && value.front() == '"' && value.back() == '"')
      value = value.substr(1, value.size() - 2);
    h.kv.emplace_back(key, value);
  }
  double nbytes = 0, xincr = 0, xzero = 0, ptoff = 0, ymult = 0, yoff = 0, yzero = 0, npt = 0;
  if (!to_double(h.get({"BYT_NR", "BYT_N"}), &nbytes) || (nbytes != 1 && nbytes != 2))
    return f.error(0, "BYT_NR missing or not 1 or 2: expected 1- or 2-byte samples");
  if (!to_double(h.get({"XINCR", "XIN"}), &xincr) || !(xincr > 0))
    return f.error(0, "XINCR missing or not positive: expected the sample interval in seconds");
  if (!to_double(h.get({"YMULT", "YMU"}), &ymult))
    return f.error(0, "YMULT missing: expected the volts per count");
  // optional: 0 when absent, refused when present but not a finite number
  struct Optional {
    const char* key;
    const char* abbrev;
    double* x;
  };
  for (const Optional& o : {Optional{"XZERO", "XZE", &xzero}, Optional{"PT_OFF", "PT_O", &ptoff},
                            Optional{"YOFF", "YOF", &yoff}, Optional{"YZERO", "YZE", &yzero}})
    if (const std::string* text = h.get({o.key, o.abbrev}); text && !to_double(text, o.x))
      return f.error(0, fmt::format("{} \"{}\": expected a finite number", o.key, *text));
  const std::string* fmt_ = h.get({"BN_FMT", "BN_F"});
  const std::string* order = h.get({"BYT_OR", "BYT_O"});
  const std::string* enc = h.get({"ENCDG", "ENC"});
  const std::string* ptfmt = h.get({"PT_FMT", "PT_F"});
  if (enc && lower(*enc).rfind("asc", 0) == 0)
    return f.error(0, "ENCDG ASCII: this reader takes binary curves (ENCDG BIN)");
  if (ptfmt && lower(*ptfmt) != "y")
    return f.error(0, fmt::format("PT_FMT {}: only Y (one value per point) is read, not "
                                  "envelope pairs",
                                  *ptfmt));
  if (fmt_ && lower(*fmt_) == "fp")
    return f.error(0, "BN_FMT FP: floating-point curves are not read: set BN_FMT RI or RP");
  double xscale = 1, yscale = 1;
  if (const std::string* xu = h.get({"XUNIT", "XUN"})) {
    std::optional<double> sc = scale_to(*xu, UnitKind::kTime);
    if (!sc) return f.error(0, fmt::format("XUNIT \"{}\": expected a time unit (s)", *xu));
    xscale = *sc;
  }
  if (const std::string* yu = h.get({"YUNIT", "YUN"})) {
    std::optional<double> sc = scale_to(*yu, UnitKind::kVolt);
    if (!sc) return f.error(0, fmt::format("YUNIT \"{}\": only volts are read", *yu));
    yscale = *sc;
  }
  const bool is_signed = !fmt_ || lower(*fmt_) != "rp";
  const bool msb = !order || lower(*order) != "lsb";
  // #<n><length>
  const size_t p = head.find('#', curve);
  if (p == std::string::npos || p + 2 > head.size() ||
      !std::isdigit(static_cast<unsigned char>(head[p + 1])) || head[p + 1] == '0')
    return f.error(curve, "':CURVE' is not followed by '#<n><length>'");
  const auto ndig = static_cast<size_t>(head[p + 1] - '0');
  uint64_t len = 0;
  if (p + 2 + ndig > head.size() ||
      std::from_chars(head.data() + p + 2, head.data() + p + 2 + ndig, len).ptr !=
          head.data() + p + 2 + ndig)
    return f.error(p, "':CURVE #' has no byte count after it");
  const uint64_t data_at = p + 2 + ndig;
  const auto width = static_cast<uint64_t>(nbytes);
  if (len % width != 0)
    return f.error(p, fmt::format("the curve block holds {} bytes: not a whole number of "
                                  "{}-byte points",
                                  len, width));
  const uint64_t points = len / width;
  if (to_double(h.get({"NR_PT", "NR_P"}), &npt) && npt > 0 && static_cast<uint64_t>(npt) != points)
    return f.error(p, fmt::format("NR_PT {} but the curve block holds {} bytes = {} points", npt,
                                  len, points));
  if (points < 2) return f.error(p, "fewer than two points in the curve");
  BinaryTrace tr;
  const std::string* wfid = h.get({"WFID", "WFI"});
  tr.name = "CH1";
  if (wfid) tr.name = wfid->substr(0, wfid->find(','));
  tr.y_unit = "V";
  tr.time_from = fmt::format("t = XZERO + (i - PT_OFF) * XINCR ({:g} + (i - {:g}) * {:g} s)", xzero,
                             ptoff, xincr);
  // v = (raw - YOFF) * YMULT + YZERO
  const Sample kind = width == 1 ? (is_signed ? Sample::kI8 : Sample::kU8)
                                 : (is_signed ? Sample::kI16 : Sample::kU16);
  if (Status st = f.samples(data_at, points, kind, msb, ymult * yscale,
                            (yzero - yoff * ymult) * yscale, &tr.v, "the curve");
      !st.ok())
    return st;
  uniform_time(&tr, (xzero - ptoff * xincr) * xscale, xincr * xscale);
  return one_trace(std::move(tr));
}

// ---- Keysight/Agilent .bin ("AG") and Rigol .bin ("RG01") ----

StatusOr<std::vector<BinaryTrace>> read_ag_bin(BinFile& f, bool rigol) {
  StatusOr<Fields> fh = f.fields(0, 12, false, "the 12-byte file header");
  if (!fh) return fh.status();
  const int64_t count = fh->s(8, 4);
  if (count < 1 || count > 64)
    return f.error(8, fmt::format("{} waveforms in the file header: expected 1 to 64", count));
  std::vector<BinaryTrace> out;
  uint64_t pos = 12;
  for (int64_t w = 1; w <= count; ++w) {
    // 140 bytes; Rigol MSO7000/8000 write 128 (no time tag, no segment index)
    StatusOr<Fields> h = f.fields(pos, 128, false, fmt::format("waveform {}'s header", w));
    if (!h) return h.status();
    const int64_t hsize = h->s(0, 4), type = h->s(4, 4), nbuf = h->s(8, 4), points = h->s(12, 4);
    const double xinc = h->f64(32), xorg = h->f64(40);
    const int64_t xunits = h->s(48, 4), yunits = h->s(52, 4);
    if (hsize < 128)
      return f.error(pos,
                     fmt::format("waveform {}: header size {}: expected 128 or more", w, hsize));
    // 1 normal, 2 peak detect, 3 average, 4/5 histograms, 6 logic (skipped: not a signal)
    const bool logic = type == 6;
    if (type != 1 && type != 3 && !logic)
      return f.error(h->at(4),
                     fmt::format("waveform {}: waveform type {} ({}): only normal (1) and "
                                 "average (3) records are read; acquire in normal mode",
                                 w, type,
                                 type == 2                ? "peak detect, min/max pairs"
                                 : type == 4 || type == 5 ? "a histogram"
                                                          : "unknown"));
    if (!logic && (points < 2 || !(xinc > 0) || !std::isfinite(xinc) || !std::isfinite(xorg)))
      return f.error(h->at(12), fmt::format("waveform {}: {} points, x increment {:g}: expected 2 "
                                            "or more points and a positive increment",
                                            w, points, xinc));
    if (!logic && xunits != 2)
      return f.error(h->at(48),
                     fmt::format("waveform {}: x unit code {}: expected 2 (seconds)", w, xunits));
    if (!logic && yunits != 1)
      return f.error(h->at(52),
                     fmt::format("waveform {}: y unit code {} (3 constant, 4 amps, 5 dB, "
                                 "6 Hz): only volts (1) are read",
                                 w, yunits));
    if (nbuf < 1 || nbuf > 16)
      return f.error(h->at(8),
                     fmt::format("waveform {}: {} data buffers: expected 1 to 16", w, nbuf));
    BinaryTrace tr;
    tr.name = h->text(112, 16);
    if (tr.name.empty()) tr.name = fmt::format("waveform {}", w);
    tr.y_unit = "V";
    // Rigol writes XOrigin as the distance from the first point to the trigger (its MSO5000
    // files have XOrigin = +points * XIncrement / 2 for a centred trigger): t0 = -XOrigin.
    const double t0 = rigol ? -xorg : xorg;
    tr.time_from = rigol
                       ? fmt::format("t = -XOrigin + i * XIncrement ({:g} + i * {:g} s)", t0, xinc)
                       : fmt::format("t = XOrigin + i * XIncrement ({:g} + i * {:g} s)", t0, xinc);
    pos += static_cast<uint64_t>(hsize);
    for (int64_t b = 1; b <= nbuf; ++b) {
      StatusOr<Fields> d = f.fields(pos, 12, false, fmt::format("waveform {}'s data header", w));
      if (!d) return d.status();
      const int64_t bh = d->s(0, 4), bsize = d->s(8, 4);
      const auto btype = d->u(4, 2), bpp = d->u(6, 2);
      if (bh < 12 || bsize < 0)
        return f.error(pos, fmt::format("waveform {}: data header size {}, buffer size {}: "
                                        "expected at least 12 and not negative",
                                        w, bh, bsize));
      const uint64_t data_at = pos + static_cast<uint64_t>(bh);
      if (Status st = f.need(data_at, static_cast<uint64_t>(bsize),
                             fmt::format("waveform {}'s data buffer", w));
          !st.ok())
        return st;
      pos = data_at + static_cast<uint64_t>(bsize);
      if (b > 1 || logic) continue;  // further buffers (counts), logic channels: not signals
      if (btype != 1 || bpp != 4)
        return f.error(d->at(4),
                       fmt::format("waveform {}: buffer type {} with {} bytes a point: only "
                                   "float32 volts (type 1) are read",
                                   w, btype, bpp));
      if (bsize % 4 != 0 || bsize / 4 != points)
        return f.error(d->at(8), fmt::format("waveform {}: {} points in the header, {} bytes of "
                                             "data",
                                             w, points, bsize));
      if (Status st = f.samples(data_at, static_cast<uint64_t>(points), Sample::kF32, false, 1.0,
                                0.0, &tr.v, fmt::format("waveform {}", w));
          !st.ok())
        return st;
    }
    if (logic) continue;
    uniform_time(&tr, t0, xinc);
    out.push_back(std::move(tr));
  }
  if (out.empty()) return f.error(8, "only logic waveforms: no analog channel to read");
  return out;
}

// ---- LeCroy .trc (LECROY_2_3) ----

StatusOr<std::vector<BinaryTrace>> read_lecroy(BinFile& f) {
  StatusOr<Fields> head = f.fields(0, std::min<uint64_t>(f.size(), 64), false, "the start");
  if (!head) return head.status();
  const std::string s(head->b.begin(), head->b.end());
  const size_t w = s.find("WAVEDESC");
  if (w == std::string::npos)
    return f.error(0, "no 'WAVEDESC' in the first 64 bytes: expected a LeCroy .trc file");
  if (w > 0 && s[0] == '#') {  // "#9000020746": a definite-length block header
    const auto nd = static_cast<size_t>(s[1] - '0');
    uint64_t len = 0;
    if (nd < 1 || nd > 9 || 2 + nd > w ||
        std::from_chars(s.data() + 2, s.data() + 2 + nd, len).ptr != s.data() + 2 + nd)
      return f.error(0, "a '#' block header that is not '#<n><length>'");
    if (len > f.size() - (2 + nd))
      return f.error(0, fmt::format("the block header '{}' says {} bytes follow, but the file "
                                    "holds {} after it: the transfer was cut short",
                                    s.substr(0, 2 + nd), len, f.size() - (2 + nd)));
  }
  StatusOr<Fields> d = f.fields(w, 346, false, "the 346-byte WAVEDESC block");
  if (!d) return d.status();
  // COMM_ORDER (0 HIFIRST, 1 LOFIRST) written in its own order: 01 00 or 00 00.
  if (d->b[34] == 1 && d->b[35] == 0) {
    d->big = false;
  } else if (d->b[34] == 0 && d->b[35] == 0) {
    d->big = true;
  } else {
    return f.error(d->at(34), fmt::format("COMM_ORDER bytes {:02x} {:02x}: expected 0 (HIFIRST) "
                                          "or 1 (LOFIRST)",
                                          d->b[34], d->b[35]));
  }
  const std::string tmpl = d->text(16, 16);
  if (tmpl != "LECROY_2_3")
    return f.error(d->at(16), fmt::format("template '{}': only LECROY_2_3 is read", tmpl));
  const uint64_t comm_type = d->u(32, 2);
  if (comm_type > 1)
    return f.error(d->at(32), fmt::format("COMM_TYPE {}: expected 0 (8-bit) or 1 (16-bit samples)",
                                          comm_type));
  const uint64_t width = comm_type == 0 ? 1 : 2;
  const int64_t desc = d->s(36, 4), user = d->s(40, 4), resd = d->s(44, 4), trig = d->s(48, 4),
                ris = d->s(52, 4), resa = d->s(56, 4), wa1 = d->s(60, 4), wa2 = d->s(64, 4);
  if (desc < 346)
    return f.error(d->at(36), fmt::format("WAVE_DESCRIPTOR {}: expected at least 346", desc));
  if (user < 0 || trig < 0 || ris < 0 || wa1 < 0)
    return f.error(d->at(40), "a negative block length in WAVEDESC");
  if (resd != 0 || resa != 0)
    return f.error(d->at(resd != 0 ? 44 : 56),
                   "a reserved block (RES_DESC1 or RES_ARRAY1) is not empty: its place in the "
                   "file is not described by LECROY_2_3");
  const uint64_t record_type = d->u(316, 2);
  static const char* kTypes[] = {"single_sweep", "interleaved (RIS)",  "histogram",
                                 "graph",        "filter_coefficient", "complex",
                                 "extrema",      "sequence_obsolete",  "centered_RIS",
                                 "peak_detect"};
  if (record_type != 0)
    return f.error(d->at(316),
                   fmt::format("RECORD_TYPE {} ({}): only single_sweep (0) records are read",
                               record_type, record_type < 10 ? kTypes[record_type] : "unknown"));
  const int64_t segments = d->s(144, 4);
  if (segments > 1)
    return f.error(d->at(144), fmt::format("SUBARRAY_COUNT {}: a sequence of {} segments; isolink "
                                           "reads one record: save a single segment",
                                           segments, segments));
  if (wa2 != 0)
    return f.error(d->at(64), fmt::format("WAVE_ARRAY_2 holds {} bytes: a second data array "
                                          "(extrema, complex) is not read",
                                          wa2));
  const int64_t sparsing = d->s(136, 4);
  if (sparsing > 1)
    return f.error(d->at(136), fmt::format("SPARSING_FACTOR {}: sparsed records are not read: "
                                           "save the full record",
                                           sparsing));
  const int64_t n = d->s(116, 4), first = d->s(124, 4), last = d->s(128, 4);
  if (n < 2 || static_cast<uint64_t>(n) * width != static_cast<uint64_t>(wa1))
    return f.error(d->at(116), fmt::format("WAVE_ARRAY_COUNT {} with {}-byte samples but "
                                           "WAVE_ARRAY_1 holds {} bytes",
                                           n, width, wa1));
  if (first < 0 || last < first + 1 || last >= n)
    return f.error(d->at(124), fmt::format("FIRST_VALID_PNT {}, LAST_VALID_PNT {}: expected 0 <= "
                                           "first < last < WAVE_ARRAY_COUNT {}",
                                           first, last, n));
  const double gain = d->f32(156), voff = d->f32(160), dt = d->f32(176), t0 = d->f64(180);
  if (!std::isfinite(gain) || gain == 0 || !std::isfinite(voff))
    return f.error(d->at(156), fmt::format("VERTICAL_GAIN {:g}, VERTICAL_OFFSET {:g}: expected "
                                           "finite numbers and a gain that is not 0",
                                           gain, voff));
  if (!(dt > 0) || !std::isfinite(dt) || !std::isfinite(t0))
    return f.error(d->at(176), fmt::format("HORIZ_INTERVAL {:g}, HORIZ_OFFSET {:g}: expected a "
                                           "positive interval and a finite offset",
                                           dt, t0));
  const std::string vunit = d->text(196, 48), hunit = d->text(244, 48);
  std::optional<double> ys = scale_to(vunit, UnitKind::kVolt);
  if (!ys) return f.error(d->at(196), fmt::format("VERTUNIT '{}': only volts are read", vunit));
  std::optional<double> xs = scale_to(hunit, UnitKind::kTime);
  if (!xs) return f.error(d->at(244), fmt::format("HORUNIT '{}': expected seconds (S)", hunit));
  const uint64_t source = d->u(344, 2);
  BinaryTrace tr;
  tr.name = source <= 3 ? fmt::format("C{}", source + 1) : d->text(96, 16);
  if (tr.name.empty()) tr.name = "waveform";
  tr.y_unit = "V";
  const uint64_t data_at = w + static_cast<uint64_t>(desc + user + trig + ris);
  if (Status st = f.need(data_at, static_cast<uint64_t>(wa1), "WAVE_ARRAY_1"); !st.ok()) return st;
  // v = VERTICAL_GAIN * raw - VERTICAL_OFFSET, over the valid points
  if (Status st = f.samples(data_at + static_cast<uint64_t>(first) * width,
                            static_cast<uint64_t>(last - first + 1),
                            width == 1 ? Sample::kI8 : Sample::kI16, d->big, gain * *ys,
                            -voff * *ys, &tr.v, "WAVE_ARRAY_1");
      !st.ok())
    return st;
  const double t_first = (t0 + static_cast<double>(first) * dt) * *xs;
  uniform_time(&tr, t_first, dt * *xs);
  tr.time_from =
      fmt::format("t = HORIZ_OFFSET + i * HORIZ_INTERVAL ({:g} + i * {:g} s)", t_first, dt * *xs);
  return one_trace(std::move(tr));
}

// ---- Tektronix .wfm (WFM#001/#002/#003) ----

// The static file information: its byte order, the version (1-3), bytes per point and where the
// curve buffer starts; one record only (no FastFrame).
struct TekStatic {
  Fields s;
  int version = 0;
  uint64_t bpp = 0;
  int64_t curve_buf = 0;
};

StatusOr<TekStatic> read_tek_static(BinFile& f) {
  StatusOr<Fields> st0 = f.fields(0, 78, false, "the 78-byte static file information");
  if (!st0) return st0.status();
  TekStatic out;
  Fields& s = out.s = std::move(*st0);
  if (s.b[0] == 0x0F && s.b[1] == 0x0F) {
    s.big = false;
  } else if (s.b[0] == 0xF0 && s.b[1] == 0xF0) {
    s.big = true;
  } else {
    return f.error(0, fmt::format("byte order mark {:02x} {:02x}: expected 0f 0f (little-endian) "
                                  "or f0 f0 (big-endian)",
                                  s.b[0], s.b[1]));
  }
  const std::string ver = s.text(2, 8);
  const size_t at = ver.find("WFM#00");
  out.version = at != std::string::npos && at + 6 < ver.size() ? ver[at + 6] - '0' : 0;
  if (out.version < 1 || out.version > 3)
    return f.error(2, fmt::format("version '{}': expected :WFM#001, :WFM#002 or :WFM#003", ver));
  out.bpp = s.u(15, 1);
  out.curve_buf = s.s(16, 4);
  const uint64_t frames = s.u(72, 4);
  if (frames != 0)
    return f.error(72, fmt::format("{} FastFrame frames: one record is read; save a single "
                                   "frame",
                                   frames + 1));
  return out;
}

// The sample type of a curve format code (WFM#003 adds uint8 and int8); none for the others.
std::optional<Sample> tek_sample_kind(int64_t format, int version) {
  switch (format) {
    case 0:
      return Sample::kI16;
    case 1:
      return Sample::kI32;
    case 2:
      return Sample::kU32;
    case 4:
      return Sample::kF32;
    case 5:
      return Sample::kF64;
    case 6:
      if (version == 3) return Sample::kU8;
      break;
    case 7:
      if (version == 3) return Sample::kI8;
      break;
    default:
      break;
  }
  return std::nullopt;
}

// The waveform's dimensions: vertical (explicit dimension 1) and time (implicit dimension 1),
// scaled to volts and seconds.
struct TekDims {
  Sample kind = Sample::kI16;
  double vscale = 0, voffset = 0, ys = 1;  // v = (raw * vscale + voffset) * ys
  double tscale = 0, toffset = 0, xs = 1;  // t = (toffset + i * tscale) * xs
};

StatusOr<TekDims> read_tek_dims(BinFile& f, const Fields& h, const TekStatic& st, size_t exp1,
                                size_t imp1) {
  TekDims d;
  d.vscale = h.f64(exp1);
  d.voffset = h.f64(exp1 + 8);
  const std::string vunit = h.text(exp1 + 20, 20);
  const int64_t format = h.s(exp1 + 72, 4), storage = h.s(exp1 + 76, 4);
  d.tscale = h.f64(imp1);
  d.toffset = h.f64(imp1 + 8);
  const std::string tunit = h.text(imp1 + 20, 20);
  std::optional<Sample> kind = tek_sample_kind(format, st.version);
  if (!kind)
    return f.error(exp1 + 72, fmt::format("curve format {}: expected int16 (0), int32 (1), uint32 "
                                          "(2), fp32 (4), fp64 (5), or in WFM#003 uint8 (6), "
                                          "int8 (7)",
                                          format));
  d.kind = *kind;
  if (width_of(*kind) != st.bpp)
    return f.error(15, fmt::format("{} bytes per point, but curve format {} has {}", st.bpp, format,
                                   width_of(*kind)));
  if (storage != 0)
    return f.error(exp1 + 76, fmt::format("storage type {} (1 min/max, 2/3 histograms, 4/5 row or "
                                          "column order): only samples (0) are read",
                                          storage));
  std::optional<double> ys = scale_to(vunit, UnitKind::kVolt);
  if (!ys)
    return f.error(exp1 + 20, fmt::format("vertical units '{}': only volts are read", vunit));
  std::optional<double> xs = scale_to(tunit, UnitKind::kTime);
  if (!xs) return f.error(imp1 + 20, fmt::format("horizontal units '{}': expected seconds", tunit));
  d.ys = *ys;
  d.xs = *xs;
  if (!std::isfinite(d.vscale) || d.vscale == 0 || !std::isfinite(d.voffset))
    return f.error(exp1, fmt::format("vertical scale {:g}, offset {:g}: expected finite numbers "
                                     "and a scale that is not 0",
                                     d.vscale, d.voffset));
  if (!(d.tscale > 0) || !std::isfinite(d.tscale) || !std::isfinite(d.toffset))
    return f.error(imp1, fmt::format("horizontal scale {:g}, offset {:g}: expected a positive "
                                     "scale and a finite offset",
                                     d.tscale, d.toffset));
  return d;
}

StatusOr<std::vector<BinaryTrace>> read_tek_wfm(BinFile& f) {
  StatusOr<TekStatic> st = read_tek_static(f);
  if (!st) return st.status();
  const Fields& s = st->s;
  const uint64_t bpp = st->bpp;
  const int64_t curve_buf = st->curve_buf;
  // Offsets of the waveform header's parts (WFM#001 lacks the summary frame type; WFM#003's
  // point density is 8 bytes, not 4).
  const size_t base = st->version == 1 ? 166 : 168;
  const size_t exp_size = st->version == 3 ? 160 : 156, imp_size = st->version == 3 ? 136 : 132;
  const size_t exp1 = base, imp1 = base + 2 * exp_size;
  const size_t update = imp1 + 2 * imp_size + 12 + 12;  // after the two time base blocks
  const size_t curve = update + 24;
  StatusOr<Fields> hd = f.fields(0, curve + 30, s.big, "the waveform header");
  if (!hd) return hd.status();
  const Fields& h = *hd;
  if (const int64_t set = h.s(78, 4); set != 0)
    return f.error(78, fmt::format("SetType {}: only a single waveform (0) is read, not "
                                   "FastFrame",
                                   set));
  if (const int64_t type = h.s(122, 4); type != 2)
    return f.error(122, fmt::format("data type {}: only a vector waveform (2, YT) is read, not "
                                    "scalars, pixel maps or waveform databases",
                                    type));
  StatusOr<TekDims> dims = read_tek_dims(f, h, *st, exp1, imp1);
  if (!dims) return dims.status();
  const TekDims& d = *dims;
  const uint64_t data_start = h.u(curve + 14, 4), post_start = h.u(curve + 18, 4);
  if (curve_buf < static_cast<int64_t>(curve + 30))
    return f.error(16, fmt::format("curve buffer at byte {}: inside the header (which ends at "
                                   "byte {})",
                                   curve_buf, curve + 30));
  if (post_start <= data_start || (post_start - data_start) % bpp != 0 ||
      (post_start - data_start) / bpp < 2)
    return f.error(curve + 14, fmt::format("data from byte {} to {} of the curve buffer: expected "
                                           "two or more whole {}-byte points",
                                           data_start, post_start, bpp));
  const uint64_t n = (post_start - data_start) / bpp;
  // the trigger's position within a sample (update spec "TT offset", in samples)
  const double tt = h.f64(update + 4);
  if (!std::isfinite(tt) || std::abs(tt) > 1)
    return f.error(update + 4,
                   fmt::format("trigger time offset {:g} samples: expected -1 to 1", tt));
  BinaryTrace tr;
  tr.name = s.text(40, 32);
  if (tr.name.empty()) tr.name = "waveform";
  tr.y_unit = "V";
  if (Status st2 = f.samples(static_cast<uint64_t>(curve_buf) + data_start, n, d.kind, s.big,
                             d.vscale * d.ys, d.voffset * d.ys, &tr.v, "the curve buffer's data");
      !st2.ok())
    return st2;
  // The first point after the precharge is at imp_dim1.offset (Tektronix's own reader,
  // tekwfm.py of Programmatic-Control-Examples, which also adds the TT offset).
  const double t_first = (d.toffset + tt * d.tscale) * d.xs;
  uniform_time(&tr, t_first, d.tscale * d.xs);
  tr.time_from =
      fmt::format("t = imp_dim1.offset + (TT offset + i) * imp_dim1.scale ({:g} + i * {:g} s)",
                  t_first, d.tscale * d.xs);
  return one_trace(std::move(tr));
}

// ---- Rigol .wfm, DS1000E/D family ----

StatusOr<std::vector<BinaryTrace>> read_rigol_wfm(BinFile& f) {
  StatusOr<Fields> hd = f.fields(0, 276, false, "the 276-byte DS1000E header");
  if (!hd) return hd.status();
  const Fields& h = *hd;
  if (h.u(0, 4) != 0x0000A5A5)
    return f.error(0, "no A5 A5 00 00 magic: expected a Rigol DS1000E/D .wfm file");
  if (const uint64_t roll = h.u(20, 4); roll != 0)
    return f.error(20, fmt::format("roll stop {}: a rolling-mode record, whose samples wrap, is "
                                   "not read: save a triggered (YT) record",
                                   roll));
  const uint64_t depth1 = h.u(28, 4);
  const bool alt = h.u(142, 1) == 4;  // alternate trigger: CH2 has its own time base
  uint64_t depth2 = h.u(232, 4);
  const bool logic = (h.u(120, 1) & 1) != 0;
  bool enabled[2];
  uint64_t need = 276;
  for (int c = 0; c < 2; ++c) {
    enabled[c] = h.u(34 + 24 * c + 15, 1) != 0;
    if (c == 1 && enabled[c] && depth2 == 0) depth2 = depth1;
    if (enabled[c]) need += c == 0 ? depth1 : depth2;
  }
  if (logic) need += 2 * depth1;
  if (!enabled[0] && !enabled[1]) return f.error(49, "neither CH1 nor CH2 is enabled");
  if (need != f.size())
    return f.error(28, fmt::format("{} + {} points and {} logic words need a {}-byte file, but it "
                                   "has {} bytes: not a DS1000E/D file (DS1000B/C and others share "
                                   "the magic), or a cut one",
                                   enabled[0] ? depth1 : 0, enabled[1] ? depth2 : 0,
                                   logic ? depth1 : 0, need, f.size()));
  std::vector<BinaryTrace> out;
  uint64_t data_at = 276;
  for (int c = 0; c < 2; ++c) {
    if (!enabled[c]) continue;
    const size_t ch = 34 + 24 * static_cast<size_t>(c);
    const uint64_t n = c == 0 ? depth1 : depth2;
    const double probe = h.f32(ch + 10);
    const int64_t scale_uv = h.s(ch + 18, 4), shift = h.s(ch + 22, 2);
    if (h.u(ch + 16, 1) != 0)
      return f.error(ch + 16, fmt::format("CH{} is inverted on the scope: whether the saved "
                                          "counts are inverted is not documented; turn Invert off",
                                          c + 1));
    if (probe != 1.0f)
      return f.error(ch + 10, fmt::format("CH{}: probe ratio {:g}: DS1000E and DS1000D files "
                                          "store the probe factor differently and the file does "
                                          "not say which scope wrote it; save with the probe set "
                                          "to 1X or export CSV",
                                          c + 1, probe));
    if (scale_uv <= 0)
      return f.error(ch + 18, fmt::format("CH{}: scale {} uV/div: expected a positive scale", c + 1,
                                          scale_uv));
    const size_t tb = (c == 1 && alt) ? 236 : 84;  // time header
    const double rate = h.f32(tb + 16);
    const int64_t offset_ps = h.s(tb + 28, 8);
    if (!(rate > 0) || !std::isfinite(rate))
      return f.error(tb + 16, fmt::format("CH{}: sample rate {:g} Sa/s: expected a positive rate",
                                          c + 1, rate));
    if (n < 2) return f.error(c == 0 ? 28 : 232, fmt::format("CH{}: {} points", c + 1, n));
    BinaryTrace tr;
    tr.name = fmt::format("CH{}", c + 1);
    tr.y_unit = "V";
    // v = (125 - raw) * s - shift * s, s = scale (uV/div) * 1e-6 / 25 counts a division
    const double sv = static_cast<double>(scale_uv) * 1e-6 / 25.0;
    if (Status st = f.samples(data_at, n, Sample::kU8, false, -sv,
                              sv * (125.0 - static_cast<double>(shift)), &tr.v,
                              fmt::format("CH{}'s data", c + 1));
        !st.ok())
      return st;
    data_at += n;
    const double dt = 1.0 / rate;
    const double t0 = static_cast<double>(offset_ps) * 1e-12 - static_cast<double>(n) * dt / 2;
    uniform_time(&tr, t0, dt);
    tr.time_from = fmt::format(
        "t = offset - points * dt / 2 + i * dt, dt = 1 / sample rate ({:g} + i * {:g} "
        "s)",
        t0, dt);
    out.push_back(std::move(tr));
  }
  return out;
}

std::string hex4(const unsigned char* b, size_t n) {
  std::string out;
  for (size_t k = 0; k < std::min<size_t>(n, 4); ++k)
    out += fmt::format("{}{:02x}", k ? " " : "", b[k]);
  return out;
}

}  // namespace

std::optional<std::string> binary_kind(const std::string& path) {
  File f(std::fopen(path.c_str(), "rb"));
  unsigned char b[64] = {};
  const size_t n = f ? std::fread(b, 1, sizeof b, f.get()) : 0;
  return binary_kind_of(path, std::string_view(reinterpret_cast<const char*>(b), n));
}

std::optional<std::string> binary_kind_of(const std::string& path, std::string_view head) {
  const std::string ext = ext_of(path);
  const std::string_view s = head.substr(0, 64);
  const size_t n = s.size();
  const auto* b = reinterpret_cast<const unsigned char*>(s.data());
  if (ext == "isf" || s.rfind(":WFMP", 0) == 0 || s.rfind(":WFMO", 0) == 0) return "tektronix isf";
  if (n >= 12 && s.rfind("AG", 0) == 0) return "keysight bin";
  if (n >= 12 && s.rfind("RG01", 0) == 0) return "rigol bin";
  if (n >= 8 && ((b[0] == 0x0F && b[1] == 0x0F) || (b[0] == 0xF0 && b[1] == 0xF0)) &&
      s.substr(2, 8).find("WFM#") != std::string_view::npos)
    return "tektronix wfm";
  if (s.find("WAVEDESC") != std::string_view::npos) return "lecroy trc";
  if (n >= 4 && b[0] == 0xA5 && b[1] == 0xA5 && b[2] == 0 && b[3] == 0) return "rigol wfm";
  if (ext == "wfm" || ext == "trc" || ext == "bin") return "binary (." + ext + ")";
  return std::nullopt;
}

StatusOr<std::vector<BinaryTrace>> read_binary(const std::string& path) {
  const std::optional<std::string> kind = binary_kind(path);
  StatusOr<BinFile> f = BinFile::open(path);
  if (!f) return f.status();
  if (kind == "tektronix isf") return read_isf(*f);
  if (kind == "keysight bin") return read_ag_bin(*f, false);
  if (kind == "rigol bin") return read_ag_bin(*f, true);
  if (kind == "lecroy trc") return read_lecroy(*f);
  if (kind == "tektronix wfm") return read_tek_wfm(*f);
  if (kind == "rigol wfm") return read_rigol_wfm(*f);
  StatusOr<Fields> head = f->fields(0, std::min<uint64_t>(f->size(), 4), false, "the start");
  const std::string first = head ? hex4(head->b.data(), head->b.size()) : "";
  return f->error(
      0, fmt::format("{} file starting with bytes '{}' is not a format isolink reads (Tektronix "
                     ".isf or .wfm WFM#001-003, Keysight .bin 'AG', Rigol .bin 'RG01', LeCroy "
                     ".trc LECROY_2_3, Rigol DS1000E/D .wfm A5 A5 00 00; not Rigol DS1000Z, "
                     "DS2000, DS4000, DS1000B/C or DHO .wfm): export the waveform as CSV from "
                     "the scope or its PC software",
                     kind ? "a " + *kind : "this", first));
}

}  // namespace isolink::eye
