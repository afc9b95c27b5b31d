#pragma once
// LCM channel names. docs/protocol.md "Channels" is the one description.
// Every name is used with the session's channel suffix appended (see
// LcmOptions::channel_suffix), so several stations can share a lab network.
namespace rms::wire::channels {

inline constexpr const char* kOperatorInput =
    "RMS_OPERATOR_INPUT";                                  // operator_station -> dynamics_proc
inline constexpr const char* kDcpFrame = "RMS_DCP_FRAME";  // dynamics_proc -> scene_proc
inline constexpr const char* kEsgFrame = "RMS_ESG_FRAME";  // scene_proc -> esg_renderer
inline constexpr const char* kStatus = "RMS_STATUS";       // every process -> monitors, log
inline constexpr const char* kDcpTelemetry =
    "RMS_DCP_TELEMETRY";  // dynamics_proc -> operator_station, monitors
inline constexpr const char* kControl =
    "RMS_CONTROL";  // rms_control, operator_station -> every process
inline constexpr const char* kOperatorState =
    "RMS_OPERATOR_STATE";  // operator_station -> esg_renderer (window), log
inline constexpr const char* kWindowKeys =
    "RMS_WINDOW_KEYS";  // esg_renderer (window) -> operator_station
inline constexpr const char* kDcpState = "RMS_DCP_STATE";  // dynamics_proc -> log (re-simulation)
inline constexpr const char* kControlAnswer =
    "RMS_CONTROL_ANSWER";  // operator_station, dynamics_proc -> rms_control, instructor, log

}  // namespace rms::wire::channels
