#include "netlists/traffic/drive.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace isolink::traffic {

double Drive::duration() const {
  return segments.empty() ? 0.0 : segments.back().end;
}

std::vector<double> Drive::corners() const {
  std::vector<double> out;
  if (segments.size() > 1) out.reserve(segments.size() - 1);
  for (size_t i = 1; i < segments.size(); ++i) out.push_back(segments[i].start);
  return out;
}

int Drive::level_at(double t) const {
  if (segments.empty() || t < segments.front().start || t >= segments.back().end) return 0;
  // First segment whose end is after t.
  auto it = std::upper_bound(segments.begin(), segments.end(), t,
                             [](double x, const DriveSegment& g) { return x < g.end; });
  return it == segments.end() ? 0 : it->level;
}

std::vector<Pulse> Drive::pulses() const {
  std::vector<Pulse> out;
  for (const DriveSegment& g : segments) {
    if (g.level != 0) out.push_back({g.start, g.end - g.start, g.level});
  }
  return out;
}

Status validate(const Timing& t) {
  const std::pair<const char*, double> fields[] = {
      {"lead", t.lead}, {"byte gap", t.byte_gap}, {"frame gap", t.frame_gap}, {"tail", t.tail}};
  for (const auto& [name, v] : fields) {
    if (!(v >= 0.0) || !std::isfinite(v)) {
      return Status::Error(fmt::format("{} {} s is invalid: it must be a time >= 0", name, v));
    }
  }
  return Status::Ok();
}

DriveBuilder::DriveBuilder(EncodingOptions encoding, Timing timing)
    : enc_(encoding), timing_(timing) {
  drive_.encoding = enc_;
}

void DriveBuilder::push(double start, double end, int level) {
  if (!(end > start)) return;
  if (!drive_.segments.empty() && drive_.segments.back().level == level) {
    drive_.segments.back().end = end;
  } else {
    drive_.segments.push_back({start, end, level});
  }
  t_ = end;
}

double DriveBuilder::next_idle() const {
  const double automatic = any_item_ ? timing_.frame_gap : timing_.lead;
  return (gap_ >= 0 ? gap_ : automatic) + pending_idle_;
}

Status DriveBuilder::set_max_duration(double seconds) {
  if (!(seconds > 0.0)) {
    return Status::Error(
        fmt::format("maximum duration {} s is invalid: it must be a positive time", seconds));
  }
  max_duration_ = seconds;
  return Status::Ok();
}

Status DriveBuilder::set_max_segments(size_t count) {
  if (count == 0) return Status::Error("maximum segment count 0 is invalid: it must be >= 1");
  max_segments_ = static_cast<double>(count);
  return Status::Ok();
}

Status DriveBuilder::check_room(double length, double segments) const {
  const double end = t_ + next_idle() + length;
  if (!(end <= max_duration_)) {
    return Status::Error(
        fmt::format("the traffic would last {:g} s by the end of this item; the limit is {:g} s",
                    end, max_duration_));
  }
  // + 1: the idle before the item.
  const double count = static_cast<double>(drive_.segments.size()) + 1 + segments;
  if (!(count <= max_segments_)) {
    return Status::Error(
        fmt::format("the traffic would have up to {:.0f} level segments by the end of this item; "
                    "the limit is {:.0f}",
                    count, max_segments_));
  }
  return Status::Ok();
}

void DriveBuilder::begin_item() {
  push(t_, t_ + next_idle(), 0);
  pending_idle_ = 0;
  gap_ = -1;
  any_item_ = true;
}

Status DriveBuilder::add_frame(const std::vector<uint8_t>& bytes, std::string label,
                               int error_bit) {
  if (bytes.empty()) return Status::Error("frame has no bytes: nothing to send");
  if (error_bit < -1 || error_bit > 1)
    return Status::Error(fmt::format("error bit {} is invalid: it must be 0 or 1", error_bit));
  EncodingOptions enc = enc_;
  if (error_bit >= 0) enc.error_bit = error_bit;
  Status s = validate(enc);
  if (!s.ok()) return s;
  s = validate(timing_);
  if (!s.ok()) return s;
  const double n = static_cast<double>(bytes.size());
  s = check_room(n * byte_duration(enc) + (n - 1) * timing_.byte_gap,
                 n * byte_half_bit_count(enc) + (n - 1));
  if (!s.ok()) return s;
  begin_item();
  DriveFrame f;
  f.kind = FrameKind::kData;
  f.label = std::move(label);
  f.bytes = bytes;
  f.start = t_;
  for (size_t i = 0; i < bytes.size(); ++i) {
    if (i) push(t_, t_ + timing_.byte_gap, 0);
    const double t0 = t_;
    f.byte_starts.push_back(t0);
    const std::vector<int> h = byte_half_bits(bytes[i], enc);
    for (size_t k = 0; k < h.size(); ++k) {
      push(t0 + static_cast<double>(k) * enc.half_bit,
           t0 + static_cast<double>(k + 1) * enc.half_bit, h[k]);
    }
  }
  f.end = t_;
  drive_.frames.push_back(std::move(f));
  return Status::Ok();
}

Status DriveBuilder::add_tone(Tone tone, const ToneOptions& opt) {
  Status s = validate(opt);
  if (!s.ok()) return s;
  s = validate(timing_);
  if (!s.ok()) return s;
  s = check_room(tone_duration(opt), 2.0 * opt.couplets);
  if (!s.ok()) return s;
  begin_item();
  DriveFrame f;
  f.kind = FrameKind::kTone;
  f.label = std::string(tone_name(tone));
  f.tone = tone;
  f.couplets = opt.couplets;
  f.start = t_;
  const double t0 = t_;
  const std::vector<int> h = tone_half_bits(tone, opt);
  for (size_t k = 0; k < h.size(); ++k) {
    push(t0 + static_cast<double>(k) * opt.pulse, t0 + static_cast<double>(k + 1) * opt.pulse,
         h[k]);
  }
  f.end = t_;
  drive_.frames.push_back(std::move(f));
  return Status::Ok();
}

Status DriveBuilder::add_idle(double seconds) {
  if (!(seconds >= 0.0) || !std::isfinite(seconds)) {
    return Status::Error(fmt::format("idle {} s is invalid: it must be a time >= 0", seconds));
  }
  pending_idle_ += seconds;
  return Status::Ok();
}

Status DriveBuilder::set_gap(double seconds) {
  if (!(seconds >= 0.0) || !std::isfinite(seconds)) {
    return Status::Error(fmt::format("gap {} s is invalid: it must be a time >= 0", seconds));
  }
  gap_ = seconds;
  return Status::Ok();
}

Drive DriveBuilder::finish() {
  const double tail = (timing_.tail >= 0.0 && std::isfinite(timing_.tail)) ? timing_.tail : 0.0;
  push(t_, t_ + tail + pending_idle_, 0);
  Drive out = std::move(drive_);
  drive_ = Drive{};
  drive_.encoding = enc_;
  t_ = 0;
  pending_idle_ = 0;
  gap_ = -1;
  any_item_ = false;
  return out;
}

double p_volts(int level, double vdd) {
  return 0.5 * vdd * (1.0 + level);
}
double n_volts(int level, double vdd) {
  return 0.5 * vdd * (1.0 - level);
}

namespace {

void emit_source(std::string& out, const std::string& name, const std::string& node,
                 const std::vector<double>& pts, int per_line) {
  out += fmt::format("{} {} 0 PWL(", name, node);
  for (size_t i = 0; i < pts.size() / 2; ++i) {
    if (i > 0) out += (per_line > 0 && i % static_cast<size_t>(per_line) == 0) ? "\n+ " : " ";
    out += fmt::format("{:.12g} {:.6g}", pts[2 * i], pts[2 * i + 1]);
  }
  out += ")\n";
}

}  // namespace

StatusOr<std::vector<double>> line_pwl(const Drive& d, int line_sign, double edge, double vdd) {
  if (!(edge > 0.0) || !std::isfinite(edge)) {
    return Status::Error(
        fmt::format("edge time {} s is invalid: it must be a positive time", edge));
  }
  if (d.segments.empty()) return Status::Error("drive is empty: nothing to write as PWL");
  double shortest = d.segments.front().end - d.segments.front().start;
  for (const DriveSegment& g : d.segments) shortest = std::min(shortest, g.end - g.start);
  if (!(edge < shortest)) {
    return Status::Error(fmt::format(
        "edge time {:g} s is too long: it must be shorter than the shortest segment ({:g} s)", edge,
        shortest));
  }
  std::vector<double> pts;
  pts.reserve(4 * d.segments.size() + 4);
  auto add = [&](double t, int level) {
    pts.push_back(t);
    pts.push_back(line_sign > 0 ? p_volts(level, vdd) : n_volts(level, vdd));
  };
  const double half = 0.5 * edge;
  add(d.segments.front().start, d.segments.front().level);
  for (size_t i = 1; i < d.segments.size(); ++i) {
    add(d.segments[i].start - half, d.segments[i - 1].level);
    add(d.segments[i].start + half, d.segments[i].level);
  }
  add(d.segments.back().end, d.segments.back().level);
  return pts;
}

StatusOr<std::string> pwl_sources(const Drive& d, const PwlOptions& opt) {
  StatusOr<std::vector<double>> p = line_pwl(d, +1, opt.edge, opt.vdd);
  if (!p) return p.status();
  StatusOr<std::vector<double>> n = line_pwl(d, -1, opt.edge, opt.vdd);
  if (!n) return n.status();
  std::string out;
  emit_source(out, opt.p_source, opt.p_node, *p, opt.points_per_line);
  emit_source(out, opt.n_source, opt.n_node, *n, opt.points_per_line);
  return out;
}

}  // namespace isolink::traffic
