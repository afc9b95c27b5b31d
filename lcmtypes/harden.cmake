# Hardens lcm-gen 1.3.1's C++ decoders against hostile input (found by
# fuzz_small_messages, docs/security.md "Fuzzing"): a string's length field
# is trusted down to zero and below, so a length of 0 makes the decoder
# assign 2^64-1 characters (std::length_error) and INT_MIN overflows
# (undefined behaviour) before any check. Every valid string carries at
# least its terminating NUL (length >= 1): refuse the rest as malformed.
# Both forms lcm-gen writes are patched: "__elem_len" (strings in arrays)
# and "__NAME_len__" (string fields).
#   cmake -DHEADERS="a.hpp;b.hpp" -P harden.cmake
foreach(h IN LISTS HEADERS)
  file(READ "${h}" text)
  string(REGEX REPLACE "if\\((__[A-Za-z0-9_]*len_*) > maxlen - pos\\) return -1;"
                       "if(\\1 <= 0 || \\1 > maxlen - pos) return -1;" text "${text}")
  file(WRITE "${h}" "${text}")
endforeach()
