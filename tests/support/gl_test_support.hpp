#pragma once
// Shared pieces of the GL tests: one headless context for the whole run, procedural test charts,
// image comparison.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/gl/egl_context.hpp"
#include "core/image.hpp"
#include "optics/depth.hpp"
#include "optics/profile.hpp"

namespace nelf::test {

// The process-wide context (EGL displays are per device, so one context serves every test).
// MESA_SHADER_CACHE_DIR points to a temporary directory first, so tests never touch ~/.cache.
std::shared_ptr<gl::EglContext> shared_gl_context();

// Photo-like chart: smooth colour gradients, hard-edged shapes and mid-frequency texture.
Image photo_chart(int width, int height);
// Zone plate cos(k r²) whose local frequency rises to the view's Nyquist limit at the corners.
Image zone_plate(int width, int height);

// PSNR (dB, peak 1) over the RGB channels; +inf for identical images. Sizes must match.
double psnr(const Image& a, const Image& b);
// Largest absolute RGB difference.
double max_abs_difference(const Image& a, const Image& b);

// hmz-t1 with a 320×180 panel of 4× the pixel pitch (same physical size and optics, 16× fewer
// pixels), so the 16×16 reference stays fast.
Profile small_panel_profile();

// A width×height disparity surface for the left eye of `profile` and views shown at `aspect`: a
// block over the left third of the view (x from 1/6 to 1/2, y from 1/4 to 3/4) at 250 mm, the rest
// on the screen.
std::shared_ptr<const DisparitySurface> near_block_surface(const Profile& profile, double aspect, int width,
                                                           int height);

// `view` averaged in `block` cells, RGBA8, as swscale's area filter hands them over.
std::vector<std::uint8_t> block_means(const Image& view, std::array<int, 2> block);

}  // namespace nelf::test
