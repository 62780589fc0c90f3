#include "eye/scope_binary.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>

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
  return ec == std::errc() && std::isfinite(*x);
}

StatusOr<std::vector<BinaryTrace>> read_isf(const std::string& path, std::FILE* f) {
  auto err = [&](const std::string& m) { return Status::Error(path + ": error: " + m); };
  std::string head(4096, '\0');
  head.resize(std::fread(head.data(), 1, head.size(), f));
  const size_t curve = head.find(":CURV");
  if (curve == std::string::npos)
    return err(
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
    return err("BYT_NR missing or not 1 or 2: expected 1- or 2-byte samples");
  if (!to_double(h.get({"XINCR", "XIN"}), &xincr) || !(xincr > 0))
    return err("XINCR missing or not positive: expected the sample interval in seconds");
  if (!to_double(h.get({"YMULT", "YMU"}), &ymult))
    return err("YMULT missing: expected the volts per count");
  to_double(h.get({"XZERO", "XZE"}), &xzero);
  to_double(h.get({"PT_OFF", "PT_O"}), &ptoff);
  to_double(h.get({"YOFF", "YOF"}), &yoff);
  to_double(h.get({"YZERO", "YZE"}), &yzero);
  const std::string* fmt_ = h.get({"BN_FMT", "BN_F"});
  const std::string* order = h.get({"BYT_OR", "BYT_O"});
  const std::string* enc = h.get({"ENCDG", "ENC"});
  const std::string* ptfmt = h.get({"PT_FMT", "PT_F"});
  if (enc && lower(*enc).rfind("asc", 0) == 0)
    return err("ENCDG ASCII: this reader takes binary curves (ENCDG BIN)");
  if (ptfmt && lower(*ptfmt) != "y")
    return err(
        fmt::format("PT_FMT {}: only Y (one value per point) is read, not envelope pairs", *ptfmt));
  const bool is_signed = !fmt_ || lower(*fmt_) != "rp";
  const bool msb = !order || lower(*order) != "lsb";
  // #<n><length>
  size_t p = head.find('#', curve);
  if (p == std::string::npos || p + 2 > head.size() ||
      !std::isdigit(static_cast<unsigned char>(head[p + 1])))
    return err("':CURVE' is not followed by '#<n><length>'");
  const int ndig = head[p + 1] - '0';
  if (ndig < 1 || p + 2 + static_cast<size_t>(ndig) > head.size())
    return err("':CURVE #' has no byte count after it");
  size_t len = 0;
  std::from_chars(head.data() + p + 2, head.data() + p + 2 + ndig, len);
  const size_t data_at = p + 2 + static_cast<size_t>(ndig);
  const size_t width = static_cast<size_t>(nbytes);
  const size_t points = len / width;
  if (to_double(h.get({"NR_PT", "NR_P"}), &npt) && npt > 0 && static_cast<size_t>(npt) != points)
    return err(
        fmt::format("NR_PT {} but the curve block holds {} bytes = {} points", npt, len, points));
  if (points < 2) return err("fewer than two points in the curve");
  BinaryTrace tr;
  const std::string* wfid = h.get({"WFID", "WFI"});
  tr.name = "CH1";
  if (wfid) tr.name = wfid->substr(0, wfid->find(','));
  if (const std::string* yu = h.get({"YUNIT", "YUN"})) tr.y_unit = *yu;
  tr.time_from = fmt::format("t = XZERO + (i - PT_OFF) * XINCR ({:g} + (i - {:g}) * {:g} s)", xzero,
                             ptoff, xincr);
  tr.t.reserve(points);
  tr.v.reserve(points);
  if (std::fseek(f, static_cast<long>(data_at), SEEK_SET) != 0) return err("cannot seek");
  std::vector<unsigned char> buf(65536 * width);
  size_t i = 0;
  while (i < points) {
    const size_t want = std::min(points - i, size_t{65536});
    if (std::fread(buf.data(), width, want, f) != want)
      return err(fmt::format("the curve ends after {} of {} points", i, points));
    for (size_t k = 0; k < want; ++k, ++i) {
      const unsigned char* b = &buf[k * width];
      double raw;
      if (width == 1) {
        raw = is_signed ? static_cast<double>(static_cast<int8_t>(b[0])) : b[0];
      } else {
        const uint16_t u =
            msb ? static_cast<uint16_t>(b[0] << 8 | b[1]) : static_cast<uint16_t>(b[1] << 8 | b[0]);
        raw = is_signed ? static_cast<double>(static_cast<int16_t>(u)) : u;
      }
      tr.t.push_back(xzero + (static_cast<double>(i) - ptoff) * xincr);
      tr.v.push_back((raw - yoff) * ymult + yzero);
    }
  }
  return std::vector<BinaryTrace>{std::move(tr)};
}

template <class T>
bool get_le(std::FILE* f, T* x) {
  unsigned char b[sizeof(T)];
  if (std::fread(b, 1, sizeof(T), f) != sizeof(T)) return false;
  std::memcpy(x, b, sizeof(T));  // the format is little-endian, as are the hosts we build on
  return true;
}

StatusOr<std::vector<BinaryTrace>> read_keysight_bin(const std::string& path, std::FILE* f) {
  auto err = [&](const std::string& m) { return Status::Error(path + ": error: " + m); };
  char cookie[2], version[2];
  int32_t file_size = 0, count = 0;
  if (std::fread(cookie, 1, 2, f) != 2 || std::fread(version, 1, 2, f) != 2 ||
      !get_le(f, &file_size) || !get_le(f, &count))
    return err("shorter than the 12-byte file header");
  if (cookie[0] != 'A' || (cookie[1] != 'G' && cookie[1] != 'R'))
    return err("no 'AG' cookie at byte 0: expected a Keysight/Agilent .bin file");
  if (count < 1 || count > 64)
    return err(fmt::format("{} waveforms in the file header: expected 1 to 64", count));
  std::vector<BinaryTrace> out;
  for (int w = 0; w < count; ++w) {
    const long start = std::ftell(f);
    int32_t hsize = 0, type = 0, nbuf = 0, points = 0, cnt = 0, xunits = 0, yunits = 0;
    float xrange = 0;
    double xdorg = 0, xinc = 0, xorg = 0;
    char date[16], time[16], frame[24], label[16];
    if (!get_le(f, &hsize) || !get_le(f, &type) || !get_le(f, &nbuf) || !get_le(f, &points) ||
        !get_le(f, &cnt) || !get_le(f, &xrange) || !get_le(f, &xdorg) || !get_le(f, &xinc) ||
        !get_le(f, &xorg) || !get_le(f, &xunits) || !get_le(f, &yunits) ||
        std::fread(date, 1, 16, f) != 16 || std::fread(time, 1, 16, f) != 16 ||
        std::fread(frame, 1, 24, f) != 24 || std::fread(label, 1, 16, f) != 16)
      return err(fmt::format("waveform {}: its header is cut short", w + 1));
    if (hsize < 140 || std::fseek(f, start + hsize, SEEK_SET) != 0)
      return err(fmt::format("waveform {}: header size {} (expected at least 140)", w + 1, hsize));
    if (points < 2 || !(xinc > 0) || !std::isfinite(xorg))
      return err(
          fmt::format("waveform {}: {} points, x increment {:g}: expected 2 or more "
                      "points and a positive increment",
                      w + 1, points, xinc));
    BinaryTrace tr;
    tr.name = std::string(label, strnlen(label, 16));
    if (tr.name.empty()) tr.name = fmt::format("waveform {}", w + 1);
    tr.y_unit = yunits == 1 ? "V" : fmt::format("unit code {}", yunits);
    tr.time_from = fmt::format("t = XOrigin + i * XIncrement ({:g} + i * {:g} s)", xorg, xinc);
    for (int b = 0; b < nbuf; ++b) {
      int32_t bh = 0, bsize = 0;
      int16_t btype = 0, bpp = 0;
      const long bstart = std::ftell(f);
      if (!get_le(f, &bh) || !get_le(f, &btype) || !get_le(f, &bpp) || !get_le(f, &bsize))
        return err(fmt::format("waveform {}: data header cut short", w + 1));
      std::fseek(f, bstart + bh, SEEK_SET);
      const bool floats = (btype == 1 || btype == 2 || btype == 3) && bpp == 4;
      if (b > 0 || !floats) {  // min/max buffers, counts, logic: skipped
        std::fseek(f, bsize, SEEK_CUR);
        if (b == 0)
          return err(
              fmt::format("waveform {}: buffer type {} with {} bytes a point: only "
                          "float32 volts (types 1-3) are read",
                          w + 1, btype, bpp));
        continue;
      }
      const size_t n = static_cast<size_t>(bsize) / 4;
      if (n != static_cast<size_t>(points))
        return err(
            fmt::format("waveform {}: {} points in the header, {} in the data", w + 1, points, n));
      tr.t.reserve(n);
      tr.v.reserve(n);
      for (size_t i = 0; i < n; ++i) {
        float y;
        if (!get_le(f, &y)) return err(fmt::format("waveform {}: data cut at point {}", w + 1, i));
        if (!std::isfinite(y) || std::abs(y) > 1e30f)
          return err(fmt::format("waveform {}: point {} is {} (a clipped or invalid sample)", w + 1,
                                 i, y));
        tr.t.push_back(xorg + static_cast<double>(i) * xinc);
        tr.v.push_back(y);
      }
    }
    if (tr.t.empty()) return err(fmt::format("waveform {}: no data buffer", w + 1));
    out.push_back(std::move(tr));
  }
  return out;
}

}  // namespace

std::optional<std::string> binary_kind(const std::string& path) {
  const std::string ext = ext_of(path);
  File f(std::fopen(path.c_str(), "rb"));
  char b[16] = {};
  const size_t n = f ? std::fread(b, 1, sizeof b, f.get()) : 0;
  if (ext == "isf" ||
      (n >= 5 && (std::strncmp(b, ":WFMP", 5) == 0 || std::strncmp(b, ":WFMO", 5) == 0)))
    return "tektronix isf";
  if (n >= 2 && b[0] == 'A' && (b[1] == 'G' || b[1] == 'R') && (ext == "bin" || n >= 12))
    return "keysight bin";
  if (ext == "wfm") return "tektronix or rigol wfm";
  if (ext == "trc") return "lecroy trc";
  if (ext == "bin") return "binary (.bin)";
  return std::nullopt;
}

StatusOr<std::vector<BinaryTrace>> read_binary(const std::string& path) {
  const std::optional<std::string> kind = binary_kind(path);
  File f(std::fopen(path.c_str(), "rb"));
  if (!f) return Status::Error(path + ": error: cannot open the file");
  if (kind == "tektronix isf") return read_isf(path, f.get());
  if (kind == "keysight bin") return read_keysight_bin(path, f.get());
  return Status::Error(fmt::format(
      "{}: error: {} captures are not read yet: export the waveform as CSV (or Tektronix .isf "
      "/ Keysight .bin) from the scope or its PC software",
      path, kind ? *kind : "binary"));
}

}  // namespace isolink::eye
