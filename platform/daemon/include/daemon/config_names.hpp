#pragma once
// The names that mcslamd's configuration file gives the enumerated settings (the values users write): the
// reader turns them into the enums, --check-config and the log write them back.
#include "daemon/rig_assembler.hpp"
#include "daemon/yaml_fields.hpp"
#include "sources/source_config.hpp"
#include "trigger/trigger_config.hpp"

namespace mcslam::platform {

inline constexpr NamedValue<SourceType> kSourceTypeNames[] = {
    {"dataset", SourceType::Dataset}, {"aravis", SourceType::Aravis}, {"sim", SourceType::Sim}};
inline constexpr NamedValue<TriggerMode> kTriggerModeNames[] = {
    {"free_running", TriggerMode::FreeRunning}, {"software", TriggerMode::Software}, {"gpio", TriggerMode::Gpio}};
inline constexpr NamedValue<ReplayRate> kReplayRateNames[] = {{"recorded", ReplayRate::Recorded},
                                                              {"fastest", ReplayRate::Fastest}};
inline constexpr NamedValue<AtEnd> kAtEndNames[] = {
    {"exit", AtEnd::Exit}, {"loop", AtEnd::Loop}, {"idle", AtEnd::Idle}};
inline constexpr NamedValue<SimPace> kSimPaceNames[] = {{"fastest", SimPace::Fastest}, {"realtime", SimPace::Realtime}};
inline constexpr NamedValue<RigAssembler::MatchBy> kMatchByNames[] = {
    {"trigger_count", RigAssembler::MatchBy::TriggerCount}, {"timestamp", RigAssembler::MatchBy::Timestamp}};

inline const char* configName(SourceType v) { return nameOf(v, kSourceTypeNames); }
inline const char* configName(TriggerMode v) { return nameOf(v, kTriggerModeNames); }
inline const char* configName(ReplayRate v) { return nameOf(v, kReplayRateNames); }
inline const char* configName(AtEnd v) { return nameOf(v, kAtEndNames); }
inline const char* configName(SimPace v) { return nameOf(v, kSimPaceNames); }
inline const char* configName(RigAssembler::MatchBy v) { return nameOf(v, kMatchByNames); }

}  // namespace mcslam::platform
