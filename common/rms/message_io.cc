#include "rms/message_io.h"

namespace rms {

const char* DecodeErrorName(DecodeError e) {
  switch (e) {
    case DecodeError::kNone: return "none";
    case DecodeError::kTooLarge: return "too_large";
    case DecodeError::kWrongType: return "wrong_type";
    case DecodeError::kTruncated: return "truncated";
    case DecodeError::kTrailingBytes: return "trailing_bytes";
    case DecodeError::kBadCount: return "bad_count";
  }
  return "unknown";
}

}  // namespace rms
