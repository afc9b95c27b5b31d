"""The values the launcher (Python) and scripts/lib.sh (shell) share with the
C++: each has its one home in a C++ header, and this test holds every copy
to it (docs/architecture.md "One home for each quantity"). A constant
changed in C++ and not here, or here and not in C++, fails."""
import os
import re
import sys

import pytest

ROOT = os.path.join(os.path.dirname(__file__), "..", "..")
sys.path.insert(0, os.path.join(ROOT, "scripts"))

from rmslab_launcher import common, study_file  # noqa: E402


def cpp_constant(header, name):
    """The value of `inline constexpr TYPE NAME = VALUE;` in header: a string
    literal, or an integer or decimal expression (std::uint64_t{1} << 20)."""
    text = open(os.path.join(ROOT, header)).read()
    m = re.search(r"inline constexpr [\w:*\s]+?\b" + name + r"\s*=\s*([^;]+);", text)
    assert m, f"{header}: no 'inline constexpr ... {name} = ...;'"
    value = m.group(1).strip()
    if value.startswith('"'):
        return value.strip('"')
    value = re.sub(r"std::\w+\{(\d+)\}", r"\1", value)
    assert re.fullmatch(r"[\d.\s<>()+*-]+", value), f"{header}: {name} = {value}: not a plain expression"
    return eval(value)  # digits and operators only (checked above)


@pytest.mark.parametrize("python_value,header,name", [
    (common.DEFAULT_URL, "transport/include/rms/transport/lcm_interface.h", "kDefaultLcmUrl"),
    (common.MAX_SPEED, "transport/include/rms/transport/process.h", "kMaxSessionSpeed"),
    (common.MAX_CPU_WAKE_LATENCY_US, "base/include/rms/base/cpu_wake_latency.h", "kMaxCpuWakeLatencyUs"),
    (common.MAX_CONFIG_BYTES, "base/include/rms/base/folder_file.h", "kMaxConfigBytes"),
    (common.MAX_JSON_BYTES, "base/include/rms/base/folder_file.h", "kMaxJsonBytes"),
    (study_file.NUM_CAMERA_STATIONS, "base/include/rms/base/config.h", "kNumCameraStations"),
])
def test_the_launchers_copy_is_the_cpp_value(python_value, header, name):
    assert python_value == cpp_constant(header, name), f"{name} in {header}"


def test_the_multicast_route_checks_use_the_default_urls_group():
    group = re.match(r"udpm://([\d.]+):", common.DEFAULT_URL).group(1)
    assert common.DEFAULT_GROUP == group
    lib = open(os.path.join(ROOT, "scripts", "lib.sh")).read()
    assert re.findall(r"ip route get ([\d.]+)", lib) == [group], "scripts/lib.sh's route check"
