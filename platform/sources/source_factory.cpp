#include "sources/source_factory.hpp"

#include "aravis/aravis_source.hpp"
#include "mcslam/core/error.hpp"
#include "sources/dataset_source.hpp"
#include "sources/sim_source.hpp"

namespace mcslam::platform {

std::unique_ptr<FrameSource> createSource(const DaemonConfig& config, const std::atomic<uint64_t>& processed) {
  if (config.source_type == "dataset") return std::make_unique<DatasetSource>(config, processed);
  if (config.source_type == "aravis") return std::make_unique<AravisSource>(config);
  if (config.source_type == "sim") return std::make_unique<SimSource>(config, processed);
  throw InputError(config.file + ": source.type: '" + config.source_type + "' is not supported");
}

}  // namespace mcslam::platform
