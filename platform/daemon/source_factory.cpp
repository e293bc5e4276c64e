#include "daemon/source_factory.hpp"

#include "aravis/aravis_source.hpp"
#include "sources/dataset_source.hpp"
#include "sources/sim_source.hpp"

namespace mcslam::platform {

std::unique_ptr<FrameSource> createSource(const DaemonConfig& config) {
  const SourceContext context = sourceContext(config);
  switch (config.source_type) {
    case SourceType::Dataset: return std::make_unique<DatasetSource>(config.dataset, context);
    case SourceType::Aravis: return std::make_unique<AravisSource>(config.aravis, context);
    case SourceType::Sim: break;
  }
  return std::make_unique<SimSource>(config.sim, context);
}

}  // namespace mcslam::platform
