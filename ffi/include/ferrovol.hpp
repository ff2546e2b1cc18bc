// ferrovol.hpp: a header-only C++17 RAII wrapper over the C ABI in ferrovol.h.
// Every handle is owned by exactly one object (movable, not copyable); every failing call
// throws ferrovol::Error carrying the FvStatus and the library's message.
// Thread use follows the C types: see ferrovol.h.
#ifndef FERROVOL_HPP
#define FERROVOL_HPP

#include "ferrovol.h"

#include <array>
#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#ifndef _WIN32
#include <unistd.h> // close (SharedImage)
#endif

namespace ferrovol {

/// A failed ferrovol call: the status and fv_last_error()'s message.
class Error : public std::runtime_error {
public:
  Error(FvStatus status, const std::string &message)
      : std::runtime_error(std::string(fv_status_name(status)) + ": " + message),
        status_(status), message_(message) {}
  FvStatus status() const noexcept { return status_; }
  /// The library's message alone (what() prefixes it with the status name).
  const std::string &message() const noexcept { return message_; }

private:
  FvStatus status_;
  std::string message_;
};

/// Throws ferrovol::Error unless `status` is FV_STATUS_OK.
inline void check(FvStatus status) {
  if (status != FV_STATUS_OK) {
    throw Error(status, fv_last_error());
  }
}

namespace detail {
template <typename T, void (*Free)(T *)> struct Deleter {
  void operator()(T *p) const noexcept { Free(p); }
};
template <typename T, void (*Free)(T *)>
using Handle = std::unique_ptr<T, Deleter<T, Free>>;
/// The C ABI takes NULL for an empty list.
template <typename T> const T *data_or_null(const std::vector<T> &v) noexcept {
  return v.empty() ? nullptr : v.data();
}
} // namespace detail

/// The library version at run time ("MAJOR.MINOR.PATCH").
inline std::string version() { return fv_version(); }

/// A GPU device (see FvContext).
class Context {
public:
  Context() {
    FvContext *c = nullptr;
    check(fv_context_new(&c));
    h_.reset(c);
  }
  FvAdapterInfo info() const {
    FvAdapterInfo i{};
    check(fv_context_info(h_.get(), &i));
    return i;
  }
  /// Whether renderers on this context can share their output (the reason in
  /// fv_last_error() when not).
  bool can_share() const noexcept { return fv_context_can_share(h_.get()); }
  /// The Vulkan device and driver UUIDs, to compare with OpenGL's before sharing memory.
  struct Uuids {
    uint8_t device[16];
    uint8_t driver[16];
  };
  Uuids uuids() const {
    Uuids u{};
    check(fv_context_uuids(h_.get(), &u.device, &u.driver));
    return u;
  }
  /// The buffers, texture views, bind groups and device memory the context holds now.
  FvDeviceMemory device_memory() const {
    FvDeviceMemory m{};
    check(fv_context_device_memory(h_.get(), &m));
    return m;
  }
  /// Loses the device on purpose, to test recovery (see fv_context_lose_device).
  void lose_device() const noexcept { fv_context_lose_device(h_.get()); }
  /// Caps the device memory the context may hold, as a smaller device would (0: no cap), to
  /// test out-of-memory handling (see fv_context_limit_device_memory).
  void limit_device_memory(uint64_t bytes) const {
    check(fv_context_limit_device_memory(h_.get(), bytes));
  }
  FvContext *get() const noexcept { return h_.get(); }

private:
  detail::Handle<FvContext, fv_context_free> h_;
};

/// Volume data copied from the caller (see FvVolume).
class Volume {
public:
  Volume(const FvVolumeDesc &desc, const void *data, size_t bytes) {
    FvVolume *v = nullptr;
    check(fv_volume_new(&desc, data, bytes, &v));
    h_.reset(v);
  }
  std::array<double, 2> range(uint32_t component = 0) const {
    double r[2] = {0.0, 0.0};
    check(fv_volume_range(h_.get(), component, &r));
    return {r[0], r[1]};
  }
  /// Per-axis point coordinates (fv_volume_set_coordinates).
  void set_coordinates(const std::vector<double> &x, const std::vector<double> &y,
                       const std::vector<double> &z) {
    check(fv_volume_set_coordinates(h_.get(), x.data(), x.size(), y.data(), y.size(),
                                    z.data(), z.size()));
  }
  const FvVolume *get() const noexcept { return h_.get(); }

private:
  detail::Handle<FvVolume, fv_volume_free> h_;
};

/// A mesh copied from the caller's VTK arrays (see FvUnstructuredVolume); the arrays may
/// be released once it is made.
class UnstructuredVolume {
public:
  explicit UnstructuredVolume(const FvUnstructuredVolumeDesc &desc) {
    FvUnstructuredVolume *v = nullptr;
    check(fv_unstructured_volume_new(&desc, &v));
    h_.reset(v);
  }
  /// A description with no arrays yet (fv_unstructured_volume_desc_default).
  static FvUnstructuredVolumeDesc default_desc() {
    FvUnstructuredVolumeDesc d{};
    check(fv_unstructured_volume_desc_default(&d, sizeof d));
    return d;
  }
  const FvUnstructuredVolume *get() const noexcept { return h_.get(); }

private:
  detail::Handle<FvUnstructuredVolume, fv_unstructured_volume_free> h_;
};

/// Colour, opacity and gradient opacity per component (see FvTransferFunction).
class TransferFunction {
public:
  explicit TransferFunction(uint32_t components = 1, bool independent = true) {
    FvTransferFunction *t = nullptr;
    check(fv_transfer_function_new(components, independent, &t));
    h_.reset(t);
  }
  /// Flat (x, r, g, b) quadruples.
  void set_color(uint32_t component, const std::vector<double> &xrgb) {
    check(fv_transfer_function_set_color(h_.get(), component, detail::data_or_null(xrgb),
                                         xrgb.size() / 4));
  }
  /// Flat (x, opacity) pairs.
  void set_opacity(uint32_t component, const std::vector<double> &xa) {
    check(fv_transfer_function_set_opacity(h_.get(), component, detail::data_or_null(xa),
                                           xa.size() / 2));
  }
  /// Flat (|gradient|, opacity) pairs; empty turns gradient opacity off.
  void set_gradient_opacity(uint32_t component, const std::vector<double> &xa) {
    check(fv_transfer_function_set_gradient_opacity(h_.get(), component,
                                                    detail::data_or_null(xa), xa.size() / 2));
  }
  void set_unit_distance(uint32_t component, double unit_distance, double weight = 1.0) {
    check(fv_transfer_function_set_unit_distance(h_.get(), component, unit_distance, weight));
  }
  /// One component's own ambient, diffuse, specular and specular power (independent
  /// components; see fv_transfer_function_set_material).
  void set_material(uint32_t component, const float (&material)[4]) {
    check(fv_transfer_function_set_material(h_.get(), component, &material));
  }
  /// Label `label`'s (1-255) own functions, read where a label-map mask gives a sample this
  /// label (see fv_transfer_function_set_label_color); empty: the first component's again.
  void set_label_color(uint32_t label, const std::vector<double> &xrgb) {
    check(fv_transfer_function_set_label_color(h_.get(), label, detail::data_or_null(xrgb),
                                               xrgb.size() / 4));
  }
  void set_label_opacity(uint32_t label, const std::vector<double> &xa) {
    check(fv_transfer_function_set_label_opacity(h_.get(), label, detail::data_or_null(xa),
                                                 xa.size() / 2));
  }
  void set_label_gradient_opacity(uint32_t label, const std::vector<double> &xa) {
    check(fv_transfer_function_set_label_gradient_opacity(
        h_.get(), label, detail::data_or_null(xa), xa.size() / 2));
  }
  /// One component's 2D transfer function: width·height RGBA floats, x (scalar) fastest (see
  /// fv_transfer_function_set_table_2d); an empty `rgba` removes it.
  void set_table_2d(uint32_t component, uint32_t width, uint32_t height,
                    const std::vector<float> &rgba, double scalar_lo, double scalar_hi,
                    double gradient_max) {
    if (!rgba.empty() && rgba.size() != 4 * static_cast<size_t>(width) * height) {
      throw Error(FV_STATUS_INVALID_ARGUMENT, "2D table: rgba holds " +
                                                  std::to_string(rgba.size()) +
                                                  " floats, width * height * 4 needed");
    }
    check(fv_transfer_function_set_table_2d(h_.get(), component, width, height,
                                            detail::data_or_null(rgba), scalar_lo, scalar_hi,
                                            gradient_max));
  }
  const FvTransferFunction *get() const noexcept { return h_.get(); }

private:
  detail::Handle<FvTransferFunction, fv_transfer_function_free> h_;
};

/// A frame read back to the CPU (see FvFrame).
class Frame {
public:
  explicit Frame(FvFrame *f) : h_(f) { fv_frame_size(f, &width_, &height_); }
  uint32_t width() const noexcept { return width_; }
  uint32_t height() const noexcept { return height_; }
  /// Premultiplied RGBA8, rows top to bottom.
  const uint8_t *rgba() const noexcept { return fv_frame_rgba(h_.get()); }
  /// Window depth, rows top to bottom.
  const float *depth() const noexcept { return fv_frame_depth(h_.get()); }
  void write_png(const std::string &path, std::array<float, 3> background = {0, 0, 0}) const {
    float bg[3] = {background[0], background[1], background[2]};
    check(fv_frame_write_png(h_.get(), path.c_str(), &bg));
  }

private:
  detail::Handle<FvFrame, fv_frame_free> h_;
  uint32_t width_ = 0;
  uint32_t height_ = 0;
};

#ifndef _WIN32
/// One exported image of the shared output path (see FvSharedImage). Owns its file
/// descriptor, closed on destruction unless release() handed it over (glImportMemoryFdEXT
/// takes it on success).
class SharedImage {
public:
  SharedImage() = default;
  explicit SharedImage(const FvSharedImage &image) : image_(image) {}
  SharedImage(SharedImage &&o) noexcept : image_(o.image_) { o.image_.fd = -1; }
  SharedImage &operator=(SharedImage &&o) noexcept {
    if (this != &o) {
      reset();
      image_ = o.image_;
      o.image_.fd = -1;
    }
    return *this;
  }
  SharedImage(const SharedImage &) = delete;
  SharedImage &operator=(const SharedImage &) = delete;
  ~SharedImage() { reset(); }
  const FvSharedImage &info() const noexcept { return image_; }
  /// The descriptor, no longer closed here.
  int release() noexcept { return std::exchange(image_.fd, -1); }

private:
  void reset() noexcept {
    if (image_.fd >= 0) {
      close(image_.fd);
      image_.fd = -1;
    }
  }
  FvSharedImage image_{-1, 0, 0, 0, 0, false, 0};
};
#endif

/// A renderer (see FvRenderer).
class Renderer {
public:
  explicit Renderer(const Context &ctx) {
    FvRenderer *r = nullptr;
    check(fv_renderer_new(ctx.get(), &r));
    h_.reset(r);
  }
  static FvRenderParams default_params() {
    FvRenderParams p{};
    check(fv_render_params_default(&p, sizeof p));
    return p;
  }
  static FvIsoParams default_iso_params() {
    FvIsoParams p{};
    check(fv_iso_params_default(&p, sizeof p));
    return p;
  }
  static FvPathTraceParams default_path_trace_params() {
    FvPathTraceParams p{};
    check(fv_path_trace_params_default(&p, sizeof p));
    return p;
  }
  void set_volume(const Volume &v) { check(fv_renderer_set_volume(h_.get(), v.get())); }
  /// Replaces the volume with a mesh (fv_renderer_set_unstructured).
  void set_unstructured(const UnstructuredVolume &v) {
    check(fv_renderer_set_unstructured(h_.get(), v.get()));
  }
  /// Volumes intermixed per sample with the main one (fv_renderer_set_intermixed_volumes);
  /// the handles each description points to may be released after the call. An empty
  /// vector clears them.
  void set_intermixed_volumes(const std::vector<FvIntermixedVolume> &volumes) {
    check(fv_renderer_set_intermixed_volumes(h_.get(), detail::data_or_null(volumes),
                                             volumes.size()));
  }
  void set_transfer_function(const TransferFunction &tf) {
    check(fv_renderer_set_transfer_function(h_.get(), tf.get()));
  }
  void set_camera(const FvCamera &camera) { check(fv_renderer_set_camera(h_.get(), &camera)); }
  void set_lights(const std::vector<FvLight> &lights) {
    check(fv_renderer_set_lights(h_.get(), detail::data_or_null(lights), lights.size()));
  }
  void set_params(const FvRenderParams &p) { check(fv_renderer_set_params(h_.get(), &p)); }
  void set_isosurface(const FvIsoParams &p) { check(fv_renderer_set_isosurface(h_.get(), &p)); }
  void set_path_tracing(const FvPathTraceParams &p) {
    check(fv_renderer_set_path_tracing(h_.get(), &p));
  }
  /// `path`: an equirectangular image, or nullptr for the built-in sky; `up`: 3 doubles or
  /// nullptr for +Y.
  void set_environment(const char *path, float intensity, const double *up,
                       double azimuth_degrees) {
    check(fv_renderer_set_environment(h_.get(), path, intensity, up, azimuth_degrees));
  }
  /// An FvOutputPath.
  void set_output_path(uint32_t path) { check(fv_renderer_set_output_path(h_.get(), path)); }
  void set_progress(FvProgressFn progress, void *user) {
    check(fv_renderer_set_progress(h_.get(), progress, user));
  }
  void set_memory_budget(uint64_t bytes) {
    check(fv_renderer_set_memory_budget(h_.get(), bytes));
  }
  // One byte per point of the volume's grid, non-zero where hidden; nullptr clears.
  void set_blanking(const uint8_t *mask, size_t count) {
    check(fv_renderer_set_blanking(h_.get(), mask, count));
  }
  /// `values`: one byte per point of the volume's grid, or nullptr to clear the mask (see
  /// fv_renderer_set_mask).
  void set_mask(const uint8_t *values, size_t count, FvMaskType type) {
    check(fv_renderer_set_mask(h_.get(), values, count, static_cast<uint32_t>(type)));
  }
  void set_max_brick_points(uint32_t points) {
    check(fv_renderer_set_max_brick_points(h_.get(), points));
  }
  /// Everything a width × height frame needs but the drawing (fv_renderer_prepare).
  void prepare(uint32_t width, uint32_t height) {
    check(fv_renderer_prepare(h_.get(), width, height));
  }
  /// `depth`: width·height window depths of opaque geometry (rows top to bottom), or empty.
  void render(uint32_t width, uint32_t height, const std::vector<float> &depth = {}) {
    check(fv_renderer_render(h_.get(), width, height, detail::data_or_null(depth), depth.size()));
  }
  /// Renders with each pixel's ray between two window depths (fv_renderer_render_between).
  void render_between(uint32_t width, uint32_t height, const std::vector<float> &near,
                      const std::vector<float> &far) {
    if (near.size() != far.size())
      throw Error(FV_STATUS_INVALID_ARGUMENT,
                  "render_between: " + std::to_string(near.size()) + " near depths but " +
                      std::to_string(far.size()) + " far ones");
    check(fv_renderer_render_between(h_.get(), width, height, near.data(), far.data(),
                                     near.size()));
  }
  /// Paths per pixel the last path-traced frame shows.
  uint32_t accumulated_samples() const {
    uint32_t n = 0;
    check(fv_renderer_accumulated_samples(h_.get(), &n));
    return n;
  }
  /// How far the path tracer's accumulation has come (waits for the GPU and reads the
  /// accumulation back: ask when the figure is wanted).
  FvConvergence convergence() const {
    FvConvergence c{};
    check(fv_renderer_convergence(h_.get(), &c));
    return c;
  }

  void prepare_targets(uint32_t width, uint32_t height) {
    check(fv_renderer_prepare_targets(h_.get(), width, height));
  }
#ifndef _WIN32
  /// One image of the shared output path (an FvTarget).
  SharedImage shared_image(uint32_t target) const {
    FvSharedImage image{-1, 0, 0, 0, 0, false, 0};
    check(fv_renderer_shared_image(h_.get(), target, &image));
    return SharedImage(image);
  }
#endif
  /// Renders with the opaque depth the host wrote into the shared depth input image.
  void render_with_shared_depth(uint32_t width, uint32_t height) {
    check(fv_renderer_render_with_shared_depth(h_.get(), width, height));
  }
  /// Waits until the last frame is finished on the GPU.
  void finish() const { check(fv_renderer_finish(h_.get())); }
  Frame read_frame() const {
    FvFrame *f = nullptr;
    check(fv_renderer_read_frame(h_.get(), &f));
    return Frame(f);
  }
  FvStats stats() const {
    FvStats s{};
    check(fv_renderer_stats(h_.get(), &s));
    return s;
  }
  FvResidency residency() const {
    FvResidency r{};
    check(fv_renderer_residency(h_.get(), &r));
    return r;
  }
  FvRenderer *get() const noexcept { return h_.get(); }

private:
  detail::Handle<FvRenderer, fv_renderer_free> h_;
};

} // namespace ferrovol

#endif // FERROVOL_HPP
