#!/usr/bin/env bash
# `nelf convert` against its natural peer (DESIGN.md §10): an ffmpeg command that decodes the same
# file and encodes the same 1280x1470 frame with the same codec settings (libx264, preset medium,
# crf 18, audio copied). The difference is what nelf adds: layout split, the light-field compositor
# (GL, llvmpipe without a GPU), frame packing and read-back. Not run by ctest; results go to
# docs/PERFORMANCE.md.
#
# usage: tests/bench/convert_vs_ffmpeg.sh [NELF] [SECONDS] [RUNS] [LAYOUT] [DEPTH]
#   NELF     the nelf binary (default build/nelf)
#   SECONDS  clip length at 24 fps (default 5)
#   RUNS     runs of each command; the median is reported (default 3)
#   LAYOUT   half: a 1920x1080 half side-by-side clip, each eye squeezed to 960x1080 (what "a 1080p
#            side-by-side movie" is; the default); full: 3840x1080, each eye 1920x1080
#   DEPTH    8: the clip is 8-bit H.264 (the default); 10: 10-bit HEVC (Main 10), which both
#            commands write as 8-bit H.264 (nelf's default for it, dithered)
set -euo pipefail
nelf=$(realpath "${1:-build/nelf}")
seconds=${2:-5}
runs=${3:-3}
layout=${4:-half}
depth=${5:-8}
export LP_NUM_THREADS=${LP_NUM_THREADS:-$(nproc)}

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export MESA_SHADER_CACHE_DIR=$work/shader-cache
export NELF_CACHE_DIR=$work/nelf-cache  # composite tables (compositor/cpu/composite_table_cache.hpp)
case $layout in
  half) clip=$work/clip.hsbs.mkv eye=960x1080 frame=1920x1080 ;;  # "hsbs": detected from the name
  full) clip=$work/clip.sbs.mkv eye=1920x1080 frame=3840x1080 ;;
  *) echo "LAYOUT must be half or full" >&2; exit 2 ;;
esac

# Side-by-side H.264 with AAC audio: a 1920x1080 test pattern per eye (hue-shifted for the right),
# scaled to the eye's size, the two side by side.
ffmpeg -nostdin -hide_banner -loglevel error -y \
  -f lavfi -i "testsrc2=s=1920x1080:r=24:d=$seconds,scale=$eye" \
  -f lavfi -i "testsrc2=s=1920x1080:r=24:d=$seconds,hue=h=180,scale=$eye" \
  -f lavfi -i "sine=frequency=440:sample_rate=48000:duration=$seconds" \
  -filter_complex "[0][1]hstack,setsar=1[v]" -map "[v]" -map 2:a \
  $(if [ "$depth" = 10 ]; then echo "-c:v libx265 -preset ultrafast -crf 20 -pix_fmt yuv420p10le -x265-params log-level=error"
    else echo "-c:v libx264 -preset veryfast -crf 20 -pix_fmt yuv420p"; fi) -c:a aac "$clip"

nelf_cmd() { "$nelf" convert "$clip" "$work/nelf.mkv" --profile hmz-t1 --quiet -y; }
ffmpeg_cmd() {
  ffmpeg -nostdin -hide_banner -loglevel error -y -i "$clip" \
    -vf scale=1280:1470 -c:v libx264 -preset medium -crf 18 -pix_fmt yuv420p -c:a copy "$work/ffmpeg.mkv"
}

# Seconds of wall time for one run of a shell function.
time_it() {
  local start end
  start=$(date +%s.%N)
  "$1"
  end=$(date +%s.%N)
  echo "$end - $start" | bc -l
}
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }

# One untimed run of each first, as a user's second conversion of the same kind would find things:
# Mesa's shader cache and nelf's composite-table cache filled, the clip in the page cache. The cold
# nelf run is reported on its own.
cold=$(time_it nelf_cmd)
time_it ffmpeg_cmd >/dev/null
printf 'cold nelf run (empty shader and table caches): %.2f s\n' "$cold"

nelf_times=() ffmpeg_times=()
for ((i = 1; i <= runs; i++)); do  # interleaved, so load from other processes hits both alike
  nelf_times+=("$(time_it nelf_cmd)")
  ffmpeg_times+=("$(time_it ffmpeg_cmd)")
  printf 'run %d: nelf %.2f s, ffmpeg %.2f s\n' "$i" "${nelf_times[-1]}" "${ffmpeg_times[-1]}"
done

frames=$(ffprobe -v error -count_packets -select_streams v:0 -show_entries stream=nb_read_packets -of csv=p=0 \
  "$work/nelf.mkv")
size=$(ffprobe -v error -select_streams v:0 -show_entries stream=width,height -of csv=s=x:p=0 "$work/nelf.mkv")
n=$(median "${nelf_times[@]}")
f=$(median "${ffmpeg_times[@]}")
codec=$([ "$depth" = 10 ] && echo "10-bit HEVC" || echo "H.264")
echo "clip: ${seconds} s, $frame $layout sbs $codec 24 fps; output ${size}, ${frames} frames, libx264 medium crf 18"
printf 'nelf convert: %.2f s (%.1f fps)\n' "$n" "$(echo "$frames / $n" | bc -l)"
printf 'ffmpeg      : %.2f s (%.1f fps)\n' "$f" "$(echo "$frames / $f" | bc -l)"
printf 'ratio       : %.2fx (median of %d runs each)\n' "$(echo "$n / $f" | bc -l)" "$runs"
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg) (LP_NUM_THREADS=$LP_NUM_THREADS, $(nproc) cores)"
