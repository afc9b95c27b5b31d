#include "rms/session/brief.h"

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "rms/base/text.h"

namespace rms::session {

namespace {

using Json = nlohmann::ordered_json;

// The frames each process sent and drew, where the counts came from, and
// what the processes refused.
void FrameLines(const Json& j, std::ostream& os) {
  const auto& fr = j["frames"];
  std::int64_t dropped = 0;
  for (const auto& [k, v] : fr["dropped"].items()) dropped += v.get<std::int64_t>();
  os << "frames: operator " << fr["operator_published"] << ", DCP " << fr["dcp_published"]
     << ", ESG " << fr["esg_published"] << ", rendered " << fr["rendered"] << ", PNG "
     << fr["png_written"] << "; dropped " << dropped << "\n";
  if (!j["log"]["stats_from_log"].empty()) {
    os << "counts of " << j["log"]["stats_from_log"].dump()
       << " from their last status reports in the log "
       << "(they wrote no stats file at exit: a full disk, a crash): the counts end where the "
          "record ends\n";
  }
  const auto& r = fr["refused"];
  if (r.value("other_session", 0) + r.value("other_sender", 0) + r.value("late", 0) +
          r.value("far_ahead", 0) >
      0) {
    os << "refused by the processes: " << r["other_session"] << " of other sessions, "
       << r["other_sender"] << " from an impostor with this session's id, " << r["late"]
       << " too late to act on (a stall), " << r["far_ahead"] << " with impossible frame numbers\n";
  }
}

// "; the CPUs' wake latency held at 0 us" after the latency, from what
// each process's request came to (summary.json timing.cpu_wake_latency):
// one state for all, or each with its processes; "" for a summary without.
std::string WakeLatencyNote(const Json& j) {
  if (!j.contains("timing") || !j["timing"].contains("cpu_wake_latency")) return "";
  std::map<std::string, std::string> by_state;  // state -> processes
  for (const auto& [process, v] : j["timing"]["cpu_wake_latency"].items()) {
    std::string state = v.is_string() ? v.get<std::string>() : "not said";
    if (state.rfind("held", 0) == 0) state = state.substr(0, state.find(" ("));
    std::string& who = by_state[state];
    who += (who.empty() ? "" : ", ") + process;
  }
  if (by_state.empty()) return "";
  if (by_state.size() == 1) return "; the CPUs' wake latency " + by_state.begin()->first;
  std::string note = "; the CPUs' wake latency";
  const char* sep = " ";
  for (const auto& [state, who] : by_state) {
    note.append(sep).append(state).append(" (").append(who).append(")");
    sep = "; ";
  }
  return note;
}

// What the record, the renderer and the video lost, and the latency.
void LossLines(const Json& j, std::ostream& os) {
  const auto& fr = j["frames"];
  if (j["log"].value("skipped_bytes", 0) > 0) {
    os << "THE LOG IS DAMAGED: " << j["log"]["skipped_bytes"] << " bytes in "
       << j["log"]["skipped_places"] << " place(s) are no event (the first from byte "
       << j["log"]["skipped_stretches"][0]["from_byte"]
       << "): read past them; what they held is not in this summary, whose counts may be "
          "short\n";
  }
  if (j["log"].value("unread_bytes", 0) > 0) {
    os << "THE LOG ENDS IN " << j["log"]["unread_bytes"]
       << " bytes that are no whole event (cut short, or damaged there): what they held is not in "
          "this summary\n";
  }
  if (j["record"].value("lost", 0) > 0) {
    // Made from journals, the log holds every frame they could be read
    // for: a frame counted lost is in no readable journal and not on the
    // wire (a damaged journal or log), or one the log's reader did not take
    // as the session's (its number went back or repeated).
    if (j["record"].value("source", "") == "journals")
      os << "the record lacks " << j["record"]["lost"]
         << " of the frames the session's processes published (a damaged journal or log, or "
            "numbers that went back or repeated: a restart's, or a sender that is not "
            "believed):";
    else
      os << "the record lost " << j["record"]["lost"]
         << " frames (the recorder fell behind, was stopped or its disk filled):";
    for (const auto& [ch, r] : j["record"]["by_channel"].items()) {
      if (r["lost"].get<std::int64_t>() > 0)
        os << " " << ch << " " << r["lost"] << " of " << r["published"];
    }
    os << "\n";
  }
  const bool wire =
      !j["record"].contains("network") || j["record"]["network"].value("present", true);
  if (!wire) {
    os << "no network recording (wire.lcmlog): the record is the processes' journals "
          "alone\n";
  } else if (j["record"].contains("network") && j["record"]["network"].value("missed", 0) > 0) {
    os << "the network's recorder missed " << j["record"]["network"]["missed"]
       << " messages (a loaded machine, a stopped recorder): the record has each from the "
          "journal of the process that sent it\n";
  }
  if (j["record"].value("journal_failed", 0) > 0) {
    os << "the processes' journals could not hold " << j["record"]["journal_failed"]
       << " messages (a full disk): the record has those the network's recorder heard\n";
  }
  if (j["record"].value("journal_unread_bytes", 0) > 0) {
    os << "the journals " << j["record"]["journals_damaged"].dump() << " hold "
       << j["record"]["journal_unread_bytes"]
       << " bytes that are no event (damaged inside, or cut short): "
       << (wire ? "the record has what the network's recorder heard of what the damage held"
                : "what the damage held is in no record (no wire.lcmlog)")
       << ", and the journals are kept in journal/\n";
  }
  if (j["ignored"].value("total", 0) > 0) {
    os << "left out " << j["ignored"]["total"]
       << " logged messages (another session's, or not believed):";
    for (const auto& [why, n] : j["ignored"]["by_reason"].items()) os << " " << why << " " << n;
    if (!j["ignored"]["other_sessions"].empty())
      os << " (sessions " << j["ignored"]["other_sessions"].dump() << ")";
    os << "\n";
  }
  if (fr.value("superseded", 0) > 0) {
    os << "renderer: " << fr["superseded"]
       << " frames overtaken by a newer one before they were drawn "
       << "(superseded): not drawn; the video repeats the image before them\n";
  }
  if (fr.value("video_dropped", 0) > 0) {
    os << "video: " << fr["video_dropped"]
       << " frames dropped (the encoder fell behind; the video is "
       << "short of the session by as much)\n";
  }
  if (j["latency"].contains("input_to_render")) {
    const auto& l = j["latency"]["input_to_render"];
    os << "operator input to rendered frame: median " << l["p50_ms"].get<double>() << " ms, p99 "
       << l["p99_ms"].get<double>() << " ms" << WakeLatencyNote(j) << "\n";
  }
}

// The modes in turn, acquisition and docking, collisions.
void OutcomeLines(const Json& j, std::ostream& os) {
  if (j["log"].value("dcp_frames", 0) == 0)
    os << "modes: none (no DCP frame in the log)";
  else if (j.contains("attempts") && !j["attempts"].empty() &&
           j["attempts"][0].contains("started_in_mode"))
    os << "modes " << j["attempts"][0]["started_in_mode"];  // a restore may start past Mode 1
  else
    os << "modes 1";
  std::size_t shown = 0;
  for (const auto& mc : j["mode_changes"]) {
    if (++shown > 8) {
      os << " ... (" << j["mode_changes"].size() - 8 << " more mode changes)";
      break;
    }
    os << " -> " << mc["to"] << " (" << HumanNumber(mc["time_s"].get<double>(), 1) << " s)";
  }
  os << "; acquired " << (j["acquired"].get<bool>() ? "yes" : "no") << ", docked "
     << (j["docked"].get<bool>() ? "yes" : "no");
  if (!j["docking"].is_null()) {
    os << " (" << HumanNumber(j["docking"]["distance_ft"].get<double>()) << " ft, "
       << HumanNumber(j["docking"]["angle_deg"].get<double>(), 2) << " deg)";
  }
  if (!j["docking"].is_null() && j["docking"].value("after_restore", false))
    os << " after a restore";
  os << "\ncollisions " << j["collisions"].size() << ", frames held " << j["held_frames"]
     << "; LCM log events " << j["log"]["events"] << "\n";
}

// Attempts, session control, faults.
void SessionLines(const Json& j, std::ostream& os) {
  if (j["attempts"].size() > 1) {
    os << "attempts: " << j["attempts"].size() << " (";
    for (std::size_t i = 0; i < j["attempts"].size(); ++i) {
      const auto& a = j["attempts"][i];
      os << (i ? "; " : "") << a["index"] << " from the " << a["started_by"].get<std::string>()
         << " at " << HumanNumber(a["start_s"].get<double>())
         << " s: " << a["outcome"].get<std::string>();
    }
    os << ")\n";
  }
  if (!j["control"].empty()) {
    std::map<std::string, int> n;
    for (const auto& c : j["control"]) ++n[c["command"].get<std::string>()];
    os << "session control sent:";
    for (const auto& [what, k] : n) os << " " << what << " " << k;
    // Each command's outcome, as the processes that acted on it answered
    // (RMS_CONTROL_ANSWER): the refusals named.
    int done = 0, unanswered = 0;
    std::vector<std::string> refused;
    for (const auto& c : j["control"]) {
      const Json& answers = c.contains("answers") ? c["answers"] : Json::array();
      bool no = false;
      std::string why;
      for (const auto& a : answers) {
        if (a["outcome"] == "refused" && !no) {
          no = true;
          why = c["command"].get<std::string>();
          if (c.contains("name")) why.append(" ").append(c["name"].get<std::string>());
          why.append(": ").append(a["text"].get<std::string>());
        }
      }
      if (no)
        refused.push_back(why);
      else if (answers.empty())
        ++unanswered;
      else
        ++done;
    }
    os << "; done " << done << ", refused " << refused.size();
    if (unanswered) os << ", unanswered " << unanswered;
    os << "\n";
    for (std::size_t i = 0; i < refused.size() && i < 5; ++i)
      os << "  refused: " << refused[i] << "\n";
    if (refused.size() > 5)
      os << "  ... and " << refused.size() - 5 << " more refused (summary.json \"control\")\n";
  }
  if (j.contains("malfunctions") && !j["malfunctions"].empty()) {
    // docs/sessions.md "Malfunctions": as the DCP took them, at session time.
    os << "malfunctions:";
    const char* sep = " ";
    for (const auto& m : j["malfunctions"]) {
      const std::string at = " at " + HumanNumber(m["time_s"].get<double>()) + " s";
      const std::string why = m["why"].get<std::string>();
      const std::string ended = why == "malfunction" ? " repaired" : " cleared by a " + why;
      for (const auto& t : m["injected"]) {
        os << sep << t.get<std::string>() << (why == "malfunction" ? "" : " (by a " + why + ")")
           << at;
        sep = "; ";
      }
      for (const auto& t : m["replaced"]) {
        os << sep << t.get<std::string>() << " replaced" << at;
        sep = "; ";
      }
      for (const auto& t : m["repaired"]) {
        os << sep << t.get<std::string>() << ended << at;
        sep = "; ";
      }
    }
    os << "\n";
  }
  // Every message of the session refused by its tag, none taken: the key
  // in the folder is not the one it ran with.
  const bool refused_by_tag =
      j["ignored"].contains("by_reason") && j["ignored"]["by_reason"].value("bad_mac", 0) > 0;
  const bool nothing_read = j.contains("log") && j["log"].is_object() &&
                            j["log"].value("dcp_frames", 0) == 0 &&
                            j["log"].value("operator_frames", 0) == 0;
  if (refused_by_tag && nothing_read) {
    os << "no message in the log carries a tag made with run/session.key: it is not the key "
          "this session ran with (another session's?), and nothing of the session was read\n";
  }
  if (j["ignored"].value("tags_unchecked", false)) {
    os << "the session's messages carry tags, but its key (run/session.key) is not in the "
          "folder: they were read WITHOUT checking them, and a stranger's message with the "
          "session's id would have been taken as its own\n";
  }
  if (!j["ignored"].value("session_id_checked", true)) {
    os << "this session has no id (made before session ids): every message in its log was read as "
          "its own\n";
  }
  if (j.contains("restarts") && !j["restarts"].empty()) {
    os << "restarted after a fault:";
    for (const auto& r : j["restarts"]) {
      os << " " << r["process"].get<std::string>() << " (exit " << r["exit_code"]
         << ", up again in " << r["restart_s"].get<double>() << " s)";
    }
    os << "\n";
  }
}

// A number of the verdict, as text ("?" when it is not one).
std::string Count(const Json& v, const char* key) {
  return v.contains(key) && v[key].is_number_integer() ? std::to_string(v[key].get<std::int64_t>())
                                                       : "?";
}

// Whether the session re-simulates (summary.json "resimulation";
// docs/sessions.md "Does it re-simulate"): one line, "re-simulates: ...".
void ResimulationLine(const Json& j, std::ostream& os) {
  if (!j.contains("resimulation") || !j["resimulation"].is_object()) return;
  const Json& v = j["resimulation"];
  const std::string what = v.value("verdict", "");
  if (what == "identical") {
    os << "re-simulates: identical (" << Count(v, "frames_identical") << " of "
       << Count(v, "frames_compared") << " DCP frames, word for word";
    const std::int64_t unchecked = v.value("frames_unchecked", std::int64_t{0}) +
                                   v.value("frames_skipped_at_start", std::int64_t{0}) +
                                   v.value("frames_filled_in", std::int64_t{0});
    const std::string note = v.value("note", std::string()),
                      log_note = v.value("log_note", std::string());
    if (unchecked > 0 || (!v.value("exact", true) && !note.empty()))
      os << "; " << unchecked << " not checked: " << note;
    if (!log_note.empty()) os << "; NOT EXACT: " << log_note;
    // What the record lacks was never re-simulated: identical is of what it holds.
    const std::int64_t lost =
        j["record"].is_object() ? j["record"].value("lost", std::int64_t{0}) : 0;
    if (lost > 0)
      os << "; NOT EXACT: the record lacks " << lost
         << " of the frames the session published, not re-simulated";
    os << ")\n";
  } else if (what == "differs") {
    os << "re-simulates: NO -- it differs from the recording at "
       << (v["first_difference"].is_string() ? v["first_difference"].get<std::string>() : "?")
       << " (" << Count(v, "frames_identical") << " of " << Count(v, "frames_compared")
       << " DCP frames identical; scripts/lab resim SESSION says more)\n";
  } else if (what == "stale") {
    os << "re-simulates: NOT KNOWN -- the verdict on file is of another log: "
       << v.value("why", std::string()) << "\n";
  } else {
    os << "re-simulates: NO -- it cannot be re-simulated: "
       << (v.contains("why") && v["why"].is_string() ? v["why"].get<std::string>() : what) << "\n";
  }
}

}  // namespace

void PrintBrief(const Json& summary, std::ostream& os) {
  FrameLines(summary, os);
  LossLines(summary, os);
  OutcomeLines(summary, os);
  SessionLines(summary, os);
  ResimulationLine(summary, os);
}

}  // namespace rms::session
