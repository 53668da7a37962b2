#include "core/carried_streams.hpp"

#include <algorithm>
#include <cmath>
#include <new>

namespace nelf {
namespace {

ffmpeg::DictionaryPtr copy_dictionary(const AVDictionary* from) {
  AVDictionary* to = nullptr;
  if (av_dict_copy(&to, from, 0) < 0) {
    av_dict_free(&to);
    throw std::bad_alloc();
  }
  return ffmpeg::DictionaryPtr(to);
}

}  // namespace

CarriedStreamLayout describe_carried_streams(const AVFormatContext& input) {
  CarriedStreamLayout layout;
  for (unsigned i = 0; i < input.nb_streams; ++i) {
    const AVStream& in = *input.streams[i];
    const AVMediaType type = in.codecpar->codec_type;
    if (type != AVMEDIA_TYPE_AUDIO && type != AVMEDIA_TYPE_SUBTITLE) continue;
    CarriedStream stream;
    stream.index = static_cast<int>(i);
    stream.codec.reset(avcodec_parameters_alloc());
    if (!stream.codec || avcodec_parameters_copy(stream.codec.get(), in.codecpar) < 0) throw std::bad_alloc();
    stream.time_base = in.time_base;
    stream.disposition = in.disposition;
    stream.metadata = copy_dictionary(in.metadata);
    layout.streams.push_back(std::move(stream));
  }
  for (unsigned i = 0; i < input.nb_chapters; ++i) {
    const AVChapter& in = *input.chapters[i];
    layout.chapters.push_back({in.id, in.time_base, in.start, in.end, copy_dictionary(in.metadata)});
  }
  layout.metadata = copy_dictionary(input.metadata);
  return layout;
}

std::vector<CarriedChapter> chapters_in_range(std::vector<CarriedChapter> chapters, double origin_s,
                                              std::optional<double> end_s) {
  std::vector<CarriedChapter> kept;
  for (CarriedChapter& chapter : chapters) {
    const double unit = av_q2d(chapter.time_base);
    if (unit <= 0.0) continue;
    const double start = static_cast<double>(chapter.start) * unit - origin_s;
    double end = static_cast<double>(chapter.end) * unit - origin_s;
    if (end_s) end = std::min(end, *end_s);
    // A chapter that ends at the start point (or begins at the end) is not in the range.
    if (end <= std::max(start, 0.0) + 1e-6) continue;
    chapter.start = std::llround(std::max(start, 0.0) / unit);
    chapter.end = std::llround(end / unit);
    kept.push_back(std::move(chapter));
  }
  return kept;
}

}  // namespace nelf
