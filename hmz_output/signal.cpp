#include "hmz_output/signal.hpp"

#include <array>

namespace nelf {
namespace {

// CEA-861 720p60 (VIC 4), 720p50 (VIC 19) and 1080p24 (VIC 32) with HDMI 1.4a frame packing: the
// active area is both eyes plus one eye's vertical blanking, so v_total doubles (750 -> 1500,
// 1125 -> 2250) at twice the 2D pixel clock (74.25 -> 148.5 MHz).
constexpr VideoTiming k720p60{1280, 1390, 1430, 1650, 1470, 1475, 1480, 1500, 148.5};
constexpr VideoTiming k720p50{1280, 1720, 1760, 1980, 1470, 1475, 1480, 1500, 148.5};
constexpr VideoTiming k1080p24{1920, 2558, 2602, 2750, 2205, 2209, 2214, 2250, 148.5};

const std::array<Signal, 7>& signals() {
  static const std::array<Signal, 7> table{{
      {"hdmi-fp-720p60", SignalKind::hdmi_frame_packing, 1280, 720, 30, k720p60, Eye::left},
      {"hdmi-fp-720p50", SignalKind::hdmi_frame_packing, 1280, 720, 30, k720p50, Eye::left},
      {"hdmi-fp-1080p24", SignalKind::hdmi_frame_packing, 1920, 1080, 45, k1080p24, Eye::left},
      {"sbs", SignalKind::side_by_side, 0, 0, 0, std::nullopt, Eye::left},
      {"tab", SignalKind::top_bottom, 0, 0, 0, std::nullopt, Eye::left},
      {"left", SignalKind::single_eye, 0, 0, 0, std::nullopt, Eye::left},
      {"right", SignalKind::single_eye, 0, 0, 0, std::nullopt, Eye::right},
  }};
  return table;
}

}  // namespace

int Signal::packed_width(int eye_w) const {
  switch (kind) {
    case SignalKind::hdmi_frame_packing:
      return eye_width;
    case SignalKind::side_by_side:
      return 2 * eye_w;
    case SignalKind::top_bottom:
    case SignalKind::single_eye:
      return eye_w;
  }
  return eye_w;
}

int Signal::packed_height(int eye_h) const {
  switch (kind) {
    case SignalKind::hdmi_frame_packing:
      return 2 * eye_height + gap_rows;
    case SignalKind::top_bottom:
      return 2 * eye_h;
    case SignalKind::side_by_side:
    case SignalKind::single_eye:
      return eye_h;
  }
  return eye_h;
}

std::optional<Signal> find_signal(std::string_view name) {
  for (const auto& s : signals())
    if (s.name == name) return s;
  return std::nullopt;
}

const std::vector<std::string_view>& signal_names() {
  static const std::vector<std::string_view> names = [] {
    std::vector<std::string_view> v;
    for (const auto& s : signals()) v.push_back(s.name);
    return v;
  }();
  return names;
}

}  // namespace nelf
