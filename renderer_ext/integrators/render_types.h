// What a render is asked for and what it returns: the options (typed, already validated by the Python
// layer, which owns their defaults), the film with its statistics, and the recorded path segments.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "film/film.h"
#include "film/pixel_filter.h"
#include "integrators/guide_tree.h"
#include "integrators/photon_aim.h"
#include "integrators/photon_map.h"
#include "spacetime/geodesic.h"

namespace wv {

// How the light strategy finds lights in curved space: flat-space proxies aimed by pilot geodesics
// (light_connection.h); or, where the metric is static and spherical, its exact lens map (lens_connection.h),
// in Kerr the Schwarzschild map as a proposal (lens_proposal.h), elsewhere the image or aimed proxies; or
// the same with Kerr's image proxies in place of the proposal (kImageConnection).
enum LightConnectionKind : int { kAimedConnection = 0, kLensConnection = 1, kImageConnection = 2 };

// Where in its pixel a camera sample goes: uniform jitter from the sample's random numbers, or the
// pixel's stratified (Owen-scrambled Sobol) sequence (core/sobol.h).
enum PixelSamplerKind : int { kIndependentPixels = 0, kSobolPixels = 1 };

// How a curved segment is traced: in closed form where the metric's light orbits have one
// (orbit_segment.h: Schwarzschild's), else integrated; or always integrated (the reference).
enum SegmentMethodKind : int { kClosedFormSegments = 0, kIntegratedSegments = 1 };

// The options of one render. The binding (bindings/module.cpp) sets every field from the options Python
// resolved against its table (warpviz/options.py: one row per option, its default and range), so the
// initial values here are zeros, not defaults: a default lives in that table alone.
struct RenderOptions {
  // Samples [sample_begin, sample_begin + spp) of every pixel, [k sample_begin, k (sample_begin + spp)) of a
  // pixel given k x spp samples (an edge or detail pixel, render_loop.h: pixel_classes): a render in passes
  // over consecutive ranges holds exactly the samples of one render of their total, so it can stop after any
  // pass and resume later.
  int spp = 0;
  int sample_begin = 0;
  uint64_t seed = 0;
  int max_depth = 0;  // geodesic segments per path
  int rr_depth = 0;   // Russian roulette from this segment on
  bool light_sampling = false;
  TraceOptions trace;  // tol, max_steps, escape_radius, max_drift (record is ignored)
  double chord_tol = 0.0;
  int segment_method = kClosedFormSegments;
  bool aim_lights = false;    // curved space: shift light proxies by a pilot geodesic's miss (light_aim.h)
  bool light_margin = false;  // ... and enlarge quad and disk proxies by that shift (lensed images are larger)
  int light_connection = kLensConnection;
  int lens_images = 0;  // lens connection: image orders sampled (0 direct, 1 round the far side, 2 a winding, ...)
  bool lens_focus = false;  // ... and a share of its light points drawn about the lens's focus (lens_focus.h)
  bool camera_light_samples = false;  // ... and the camera's own light samples where a light's image is small
  // ... and Russian roulette on its light samples: one whose estimate is below light_roulette times the
  // largest on its path so far is traced with probability estimate / threshold (0: every one is traced).
  double light_roulette = 0.0;
  int pixel_sampler = kSobolPixels;
  bool stratified_paths = false;  // with kSobolPixels: each bounce's light point and BSDF direction too
  // Pixels on the edge of a light seen directly or in mirrors and glass, or seeing one in glass by some
  // samples' Fresnel choice only, get edge_samples x spp samples: the lamp's edge inside a pixel (a lensed
  // lamp's thin arcs) and its reflection in glass are noise no light connection touches.
  int edge_samples = 0;
  // Pixels whose footprint holds more than one surface, seen directly or in mirrors and glass (an object's
  // outline, the squeezed images of the room round a hole's shadow, the room in a glass ball), get
  // detail_samples x spp samples (an edge pixel the larger of the two multiples): the denoiser cannot rebuild
  // detail below a pixel from its features, so that is where a denoised image's error is (render_loop.h).
  int detail_samples = 0;
  // The window's edge and detail pixels (RenderResult::pixel_classes) when a previous range found them: the
  // probes are then not traced again.
  bool classes_given = false;
  std::vector<int64_t> classes;
  // Path guiding (guide_training.h): training iterations of 1, 2, 4, ... up to guide_training samples per
  // point of a grid over the image, whose last tree draws half of each diffuse vertex's directions; 0: off.
  int guide_training = 0;
  // The tree an earlier range of the same render trained (RenderResult::guide): used instead of training.
  std::shared_ptr<const GuideTree> guide;
  // Caustics by photons (photon_tracer.h): photons traced from the lights per photon pass (one per sample
  // index; 0: off), and the first pass's gather radius in pixels' footprints at the gather point.
  int64_t photons = 0;
  double photon_radius = 0.0;
  // ... and the light a hole turns back onto diffuse surfaces (a segment that turned by more than 120 degrees
  // from a photon light), stored by the same passes, which the path tracer then leaves to them.
  bool retro_photons = false;
  // ... and sent where they can be stored (photon_aim.h: a projection map of each light learnt before the first
  // pass; their flux divided by the density ratio).
  bool photon_aim = false;
  // The marks an earlier range of the same render learnt (RenderResult::photon_aim): used instead of learning.
  std::shared_ptr<const PhotonAim> photon_aim_marks;
  int filter = kBoxFilter;     // pixel reconstruction filter (film/pixel_filter.h), by importance sampling
  double filter_radius = 0.0;  // its support's half-width in pixels
  bool batch = false;      // curved space: step the geodesics of many samples together in SIMD lanes
  // Local error tolerance of pilot geodesics (at least trace.tol). A pilot only decides where a light's
  // proxy is seen from, never what a sample is worth, so its accuracy cannot bias the image.
  double pilot_tol = 0.0;
  int threads = 0;
  int crop[4] = {0, 0, 0, 0};  // window (x0, y0, width, height) of the image to render; width 0: all of it
  FilmAovs aovs;               // the AOVs the film keeps
  // The sums of the earlier ranges' samples ([0, sample_begin)), continued (moved from; same window and
  // AOVs), or null: an empty film. Samples are added in sample order either way, so a render in ranges
  // gives the bits of one render of them all.
  Film* film_in = nullptr;
  std::vector<int32_t> record_pixels;  // (x, y) image pixel pairs whose paths are recorded
  int record_samples = 0;              // ... their samples [0, record_samples) (of whichever ranges)
  // Called from the calling thread every ~20 ms with (samples done, samples total); false cancels.
  std::function<bool(int64_t, int64_t)> poll;
};

// Whether a diffuse vertex's light strategy uses the lens connection (lens_connection.h) where it applies, rather
// than the aimed proxies everywhere.
inline bool lens_connection_on(const RenderOptions& o) { return o.light_connection != kAimedConnection; }

// Whether the light strategy draws every image of a light by the spacetime's exact lens map (a static spherical
// metric with the lens connection on): it then draws the light a hole turns back itself, and needs no photons
// for it (PhotonTracer::retro).
template <class M>
bool exact_light_strategy(const RenderOptions& o) {
  return M::kStaticSpherical && o.light_sampling && lens_connection_on(o);
}

// What a pixel's probes found (render_loop.h: pixel_classes): its samples are a multiple of spp by its class.
// A bright edge pixel holds the edge of an emitter seen at kBrightEdgeRatio or more times the radiance of the
// scene's faintest emitter (a sun seen past a hole or through a throat from a room its lamp lights): its noise
// per sample grows with that radiance, and it gets kBrightEdgeFactor x edge_samples x spp samples.
enum PixelClass : int { kPlainPixel = 0, kDetailPixel = 1, kEdgePixel = 2, kBrightEdgePixel = 3 };
constexpr int64_t kPixelClasses = 4;  // pixel_classes entries: kPixelClasses * index + class
constexpr double kBrightEdgeRatio = 64.0;
constexpr int64_t kBrightEdgeFactor = 8;

// A photon pass's photons: `photons` plus `photons_per_pixel` per pixel of the whole image (every crop and tile
// traces the whole image's pass), and the most memory such a pass holds at once (every photon stored:
// photon_tracer.h), which warpviz/render/memory.py counts through the binding.
inline int64_t pass_photons(int64_t photons, double per_pixel, int width, int height) {
  return photons + int64_t(std::llround(per_pixel * double(width) * double(height)));
}
inline constexpr size_t kPhotonPassBytes = 2 * sizeof(Photon) + sizeof(uint32_t) + 1;

// The multiples of spp that a render's pixels get, by class: the one definition (render_loop.h, and Python's
// resume through the binding). An edge pixel gets the larger of edge_samples and detail_samples, a bright edge
// pixel kBrightEdgeFactor x that where edge_samples is on (> 1), else as an edge pixel.
struct SampleMultiples {
  int64_t plain = 1, detail = 1, edge = 1, bright_edge = 1;
};
inline SampleMultiples sample_multiples(int edge_samples, int detail_samples) {
  SampleMultiples m;
  m.detail = std::max(1, detail_samples);
  m.edge = std::max<int64_t>(std::max(1, edge_samples), m.detail);
  m.bright_edge = edge_samples > 1 ? m.edge * kBrightEdgeFactor : m.edge;
  return m;
}

// What the camera ray through one point of the probe lattice sees (PathTracer::probe): `light`, a signature of
// its specular branches that end on an emitter (0: none; kProbeMixed where some do and some do not); `shape`,
// a signature of where every branch ends (which object, the sky, the hole).
constexpr int32_t kProbeMixed = -1;
struct ProbeHit {
  int32_t light = 0;
  uint32_t shape = 0;
  float radiance = 0.0f;  // the brightest emitter its branches end on (the largest channel, times the branch's share)
  bool captured = false;  // some followed branch ends in a horizon
  bool specular = false;  // some followed branch met a mirror or glass
};

enum SegmentKind : int8_t { kCameraSegment = 0, kBounceSegment = 1, kLightSegment = 2 };

struct RecordedSegment {
  Track track;
  int32_t px, py, sample, bounce;
  int8_t kind, status;
  int32_t sheet;
};

// What a chunk of samples counts (summed into RenderResult): geodesic segments by RayStatus, integration
// steps, segments traced (pilots included).
struct RenderStats {
  int64_t counts[6] = {0, 0, 0, 0, 0, 0};
  int64_t steps = 0, segments = 0;
  // BSDF samples at diffuse vertices that reached a light's lit side where the light strategy also sampled, and
  // those of them that the light strategy could not have drawn (its pdf 0 there: an image order it does not sample,
  // a Kerr image its proxy misses): brought at full weight, the fireflies MIS cannot tame.
  int64_t light_hits = 0, unsampled_light_hits = 0;

  void add(const RenderStats& o) {
    for (int k = 0; k < 6; ++k) counts[k] += o.counts[k];
    steps += o.steps;
    segments += o.segments;
    light_hits += o.light_hits;
    unsampled_light_hits += o.unsampled_light_hits;
  }
};

struct RenderResult {
  Film film;
  bool completed = true;
  // The camera paths' and the probes' counts; `segments` and `steps` also the guide training's and the photons'.
  RenderStats stats;
  int64_t edge_pixels = 0;         // pixels given max(edge_samples, detail_samples) x spp samples (or more:)
  int64_t bright_edge_pixels = 0;  // ... those of them given kBrightEdgeFactor x that
  int64_t detail_pixels = 0;  // (other) pixels given detail_samples x spp samples
  // Those pixels, ascending: kPixelClasses * (index into the window) + their PixelClass.
  std::vector<int64_t> pixel_classes;
  int num_columns = 0;
  std::vector<RecordedSegment> recorded;
  std::shared_ptr<const GuideTree> guide;  // path guiding's tree (trained here, or the one handed in)
  int64_t guide_segments = 0;              // segments its training traced here (also in `segments`)
  std::shared_ptr<const PhotonAim> photon_aim;  // the photons' marks (photon_aim.h: learnt here, or handed in)
  int64_t photon_segments = 0;             // segments the photons traced (also in `segments`)
  int64_t photon_passes = 0;               // photon passes traced
  int64_t photons_stored = 0;              // photons stored, over all passes
};

}  // namespace wv
