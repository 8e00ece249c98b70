// Memory available to this process, and the refusal of an allocation that cannot fit in it:
// no input may make pt allocate more than the machine has.
#pragma once

#include <cstdint>
#include <string>

namespace pt {

// Bytes this process can still allocate: MemAvailable from /proc/meminfo (sysconf's available
// pages where that is missing), capped by what RLIMIT_AS (`ulimit -v`) leaves above the
// process's current virtual size.
std::uint64_t availableMemoryBytes();

// Throws InputError "<what> needs 40.0 GiB (<detail>), but only 23.1 GiB of memory is
// available" when `bytes` exceeds `available`.
void checkFitsInMemory(std::uint64_t bytes, const std::string& what, const std::string& detail,
                       std::uint64_t available);

// The same against availableMemoryBytes().
void checkFitsInMemory(std::uint64_t bytes, const std::string& what, const std::string& detail);

}  // namespace pt
