#include "core/carried_streams.hpp"

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

}  // namespace nelf
