#include "inputs/photo_prefetch.h"

#include <algorithm>

namespace vbrdf {

PhotoPrefetch::PhotoPrefetch(PhotoCache &cache, std::vector<PhotoRequest> requests, unsigned threads)
    : cache_(cache), requests_(std::move(requests)), errors_(requests_.size()) {
  if (threads == 0) threads = std::min(4u, std::max(1u, std::thread::hardware_concurrency()));
  threads = unsigned(std::min<size_t>(threads, requests_.size()));
  for (unsigned i = 0; i < threads; ++i) workers_.emplace_back([this] { work(); });
}

PhotoPrefetch::~PhotoPrefetch() {
  stop_ = true;
  join();
}

void PhotoPrefetch::work() {
  while (!stop_) {
    const size_t i = next_++;
    if (i >= requests_.size()) return;
    // Only what the budget holds: a photo decoded now and evicted before use is a wasted decode.
    try {
      if (!cache_.prefetch(requests_[i].path, requests_[i].width, requests_[i].height)) {
        stop_ = true;
        return;
      }
    } catch (...) {
      errors_[i] = std::current_exception();
    }
  }
}

void PhotoPrefetch::join() {
  for (std::thread &t : workers_)
    if (t.joinable()) t.join();
  workers_.clear();
}

void PhotoPrefetch::finish() {
  join();
  for (const std::exception_ptr &e : errors_)
    if (e) std::rethrow_exception(e);
}

std::unique_ptr<PhotoPrefetch> start_photo_prefetch(PhotoCache &cache, const std::vector<Raster> &rasters) {
  std::vector<PhotoRequest> requests;
  for (const Raster &r : rasters) requests.push_back({r.image_path, r.width(), r.height()});
  if (!requests.empty()) cache.get(requests.front().path, requests.front().width, requests.front().height);
  return std::unique_ptr<PhotoPrefetch>(new PhotoPrefetch(cache, std::move(requests)));
}

} // namespace vbrdf
