// SPDX-License-Identifier: MIT
// Fuzz target: a datagram on the virtual CAN bus (python-can's udp_multicast format), decoded
// as the firmware's bus receiver does; an accepted frame must encode back to a datagram that
// decodes to the same frame.
#include <string.h>

#include "fuzz.h"
#include "vcan_codec.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    hal_can_frame_t f;
    double ts = 0.0;
    if (vcan_decode(data, size, &f, &ts) != 0) {
        return 0;
    }
    if (f.dlc > 8u) {
        __builtin_trap();
    }
    uint8_t buf[256];
    const int n = vcan_encode(&f, ts == ts ? ts : 0.0, buf, sizeof buf);
    if (n > 0) {
        hal_can_frame_t g;
        double ts2;
        if (vcan_decode(buf, (size_t)n, &g, &ts2) != 0 || g.id != f.id || g.dlc != f.dlc ||
            g.flags != f.flags ||
            (!(f.flags & HAL_CAN_FLAG_REMOTE) && memcmp(g.data, f.data, f.dlc) != 0)) {
            __builtin_trap();
        }
    }
    return 0;
}
