#pragma once
// The session's record (docs/sessions.md "The record"): SESSION/lcmlog made
// from what each process wrote to its own journal as it published
// (SESSION/journal/PROCESS.N.lcmlog, rms/transport/journal.h) and what the
// network delivered to the session's recorder (SESSION/wire.lcmlog, kept as
// it is). Every journal event is in the record; a recorder's event is in it
// when no journal has the same message (the same channel and bytes: a
// message of a process that keeps no journal -- scripts/lab control, a
// stranger -- or one a journal lost to a full disk). Events are in time order
// (a journal's publish time, the recorder's receive time), each journal's
// and the recorder's own order kept. So a message the recorder missed is a
// loss of the wire (counted in record.json), not of the record.
#include <nlohmann/json.hpp>
#include <string>

namespace rms::session {

struct RecordOptions {
  bool keep_journals = false;  // leave SESSION/journal/ as it is once the record is made
};

// Makes SESSION/lcmlog (written beside and renamed: never a part of one) and
// SESSION/record.json, which it returns; then removes the journals it took
// (unless keep_journals). A session with no journal/ folder is left as it
// is ({"made": false, ...}: an older session, or one already made). Throws
// rms::InputError naming the file and the reason when a source cannot be
// read or the record cannot be written whole (the sources are then left as
// they were).
nlohmann::ordered_json MakeRecord(const std::string& session_dir,
                                  const RecordOptions& options = {});

}  // namespace rms::session
