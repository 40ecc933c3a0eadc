// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 port: the bxCAN controller, CAN1 (RM0090 chapter 32).
//
// Transmit: three mailboxes, the first empty one is used; when all three are busy the frame is
// refused (FW_ERR_FULL) rather than waited for: the firmware's periodic frames are simply sent
// again next cycle, and waiting would stall the scheduler on a disconnected bus. MCR.TXFP makes
// the mailboxes go out in request order. Receive: FIFO 0 only (3 frames deep), drained by its
// interrupt. Filters: 16-bit identifier-list mode, four standard ids per bank, so the
// controller itself drops every frame the firmware has no use for.
#include "stm32f4/stm32f4_drivers.h"

#define CAN_TQ_MIN 8u
#define CAN_TQ_MAX 25u
#define CAN_BRP_MAX 1024u
#define CAN_BS1_MAX 16u
#define CAN_BS2_MAX 8u
#define CAN_SAMPLE_TARGET_PERMILLE 875u

int stm32f4_can_timing(uint32_t pclk_hz, uint32_t bitrate, stm32f4_can_timing_t *out)
{
    if (bitrate == 0u || pclk_hz == 0u) {
        return FW_ERR_INVAL;
    }
    bool found = false;
    uint32_t best_err = 0;
    for (uint32_t tq = CAN_TQ_MAX; tq >= CAN_TQ_MIN; tq--) {
        const uint64_t per_bit = (uint64_t)bitrate * tq;
        if (pclk_hz % per_bit != 0u) {
            continue;  // only exact bit rates: every node on the bus must agree
        }
        const uint64_t brp = pclk_hz / per_bit;
        if (brp < 1u || brp > CAN_BRP_MAX) {
            continue;
        }
        // Sample point after 1 + bs1 quanta of tq; bs2 = tq - 1 - bs1.
        for (uint32_t bs2 = 1; bs2 <= CAN_BS2_MAX; bs2++) {
            const uint32_t bs1 = tq - 1u - bs2;
            if (bs1 < 1u || bs1 > CAN_BS1_MAX || bs2 > bs1) {
                continue;
            }
            const uint32_t sp = 1000u * (1u + bs1) / tq;
            const uint32_t err = sp > CAN_SAMPLE_TARGET_PERMILLE ? sp - CAN_SAMPLE_TARGET_PERMILLE
                                                                 : CAN_SAMPLE_TARGET_PERMILLE - sp;
            if (!found || err < best_err) {
                found = true;
                best_err = err;
                out->brp = (uint32_t)brp;
                out->bs1 = bs1;
                out->bs2 = bs2;
                out->sjw = 1u;
            }
        }
    }
    return found ? FW_OK : FW_ERR_INVAL;
}

uint32_t stm32f4_can_btr(const stm32f4_can_timing_t *t)
{
    return ((t->sjw - 1u) << 24) | ((t->bs2 - 1u) << 20) | ((t->bs1 - 1u) << 16) | (t->brp - 1u);
}

// A standard id in the 16-bit filter format: STID[10:0] in bits 15:5, RTR 4, IDE 3 (both 0).
static uint32_t filter16_(uint32_t id)
{
    return (id & HAL_CAN_STD_ID_MAX) << 5;
}

static void setup_filters_(stm32f4_can_t *can, const uint32_t *ids, uint32_t n_ids)
{
    const uint32_t banks_mask = (1u << STM32F4_CFG_CAN1_FILTER_BANKS) - 1u;
    can->FMR |= CAN_FMR_FINIT;
    can->FA1R &= ~banks_mask;
    if (n_ids == 0u) {
        // Bank 0, 32-bit mask mode with a zero mask: every frame matches.
        can->FM1R &= ~1u;
        can->FS1R |= 1u;
        can->filter[0].FR1 = 0u;
        can->filter[0].FR2 = 0u;
        can->FFA1R &= ~1u;
        can->FA1R |= 1u;
    } else {
        const uint32_t banks = (n_ids + 3u) / 4u;
        for (uint32_t b = 0; b < banks; b++) {
            uint32_t slot[4];
            for (uint32_t k = 0; k < 4u; k++) {
                const uint32_t i = 4u * b + k;
                slot[k] = filter16_(ids[i < n_ids ? i : n_ids - 1u]);  // pad with the last id
            }
            const uint32_t bit = 1u << b;
            can->FM1R |= bit;    // identifier list
            can->FS1R &= ~bit;   // 16-bit scale
            can->FFA1R &= ~bit;  // FIFO 0
            can->filter[b].FR1 = slot[0] | (slot[1] << 16);
            can->filter[b].FR2 = slot[2] | (slot[3] << 16);
            can->FA1R |= bit;
        }
    }
    can->FMR &= ~CAN_FMR_FINIT;
}

int stm32f4_can_setup(stm32f4_can_t *can, uint32_t pclk_hz, uint32_t bitrate,
                      const uint32_t *accept_ids, uint32_t n_ids)
{
    stm32f4_can_timing_t t;
    if (stm32f4_can_timing(pclk_hz, bitrate, &t) != FW_OK || n_ids > STM32F4_CAN_MAX_IDS ||
        (n_ids > 0u && accept_ids == NULL)) {
        return FW_ERR_INVAL;
    }
    for (uint32_t i = 0; i < n_ids; i++) {
        if (accept_ids[i] > HAL_CAN_STD_ID_MAX) {
            return FW_ERR_INVAL;
        }
    }
    // Leave sleep (the reset state), request initialisation, wait for the acknowledge.
    can->MCR = (can->MCR & ~CAN_MCR_SLEEP) | CAN_MCR_INRQ;
    if (stm32f4_wait_bits(&can->MSR, CAN_MSR_INAK | CAN_MSR_SLAK, CAN_MSR_INAK,
                          STM32F4_CFG_SHORT_WAIT_POLLS) != FW_OK) {
        return FW_ERR_IO;
    }
    can->MCR = CAN_MCR_INRQ | CAN_MCR_ABOM | CAN_MCR_TXFP;
    can->BTR = stm32f4_can_btr(&t);
    setup_filters_(can, accept_ids, n_ids);
    can->IER = CAN_IER_FMPIE0 | CAN_IER_FOVIE0 | CAN_IER_ERRIE | CAN_IER_EWGIE | CAN_IER_EPVIE |
               CAN_IER_BOFIE;
    // Leave initialisation: the controller waits for 11 recessive bits (bus idle) before it
    // acknowledges, so a bus held dominant or a missing transceiver ends in FW_ERR_IO here.
    can->MCR &= ~CAN_MCR_INRQ;
    if (stm32f4_wait_bits(&can->MSR, CAN_MSR_INAK, 0u, STM32F4_CFG_SHORT_WAIT_POLLS) != FW_OK) {
        return FW_ERR_IO;
    }
    return FW_OK;
}

int stm32f4_can_write(stm32f4_can_t *can, const hal_can_frame_t *frame)
{
    const bool ext = (frame->flags & HAL_CAN_FLAG_EXTENDED) != 0u;
    if (frame->dlc > HAL_CAN_MAX_DLC ||
        (frame->flags & ~(HAL_CAN_FLAG_EXTENDED | HAL_CAN_FLAG_REMOTE)) != 0u ||
        frame->id > (ext ? HAL_CAN_EXT_ID_MAX : HAL_CAN_STD_ID_MAX)) {
        return FW_ERR_INVAL;
    }
    const uint32_t tsr = can->TSR;
    for (uint32_t m = 0; m < 3u; m++) {
        if ((tsr & (CAN_TSR_TME0 << m)) == 0u) {
            continue;
        }
        stm32f4_can_tx_mailbox_t *mb = &can->tx[m];
        const uint8_t *d = frame->data;
        mb->TDTR = frame->dlc;
        mb->TDLR = (uint32_t)d[0] | (uint32_t)d[1] << 8 | (uint32_t)d[2] << 16 |
                   (uint32_t)d[3] << 24;
        mb->TDHR = (uint32_t)d[4] | (uint32_t)d[5] << 8 | (uint32_t)d[6] << 16 |
                   (uint32_t)d[7] << 24;
        uint32_t tir = ext ? (frame->id << CAN_IR_EXID_SHIFT) | CAN_IR_IDE
                           : frame->id << CAN_IR_STID_SHIFT;
        if (frame->flags & HAL_CAN_FLAG_REMOTE) {
            tir |= CAN_IR_RTR;
        }
        mb->TIR = tir | CAN_TIR_TXRQ;  // the request bit last: the mailbox is complete
        return (int)m;
    }
    return FW_ERR_FULL;
}

bool stm32f4_can_read(stm32f4_can_t *can, hal_can_frame_t *frame, bool *overrun)
{
    const uint32_t rf0r = can->RF0R;
    *overrun = (rf0r & CAN_RF0R_FOVR0) != 0u;
    // Write-1-to-clear flag; RFOM0 ignores a 0. One write does both the clear and the release.
    const uint32_t clear = *overrun ? CAN_RF0R_FOVR0 : 0u;
    if ((rf0r & CAN_RF0R_RFOM0) != 0u || (rf0r & CAN_RF0R_FMP0_MASK) == 0u) {
        // Empty, or the last release not done yet (FMP0 and the mailbox are stale until it is).
        if (clear != 0u) {
            can->RF0R = clear;
        }
        return false;
    }
    const stm32f4_can_rx_fifo_t *mb = &can->rx[0];
    const uint32_t rir = mb->RIR;
    const uint32_t lo = mb->RDLR;
    const uint32_t hi = mb->RDHR;
    uint32_t dlc = mb->RDTR & CAN_DTR_DLC_MASK;
    if (dlc > HAL_CAN_MAX_DLC) {
        dlc = HAL_CAN_MAX_DLC;  // classic CAN: codes 9..15 still mean 8 bytes
    }
    frame->flags = 0u;
    if (rir & CAN_IR_IDE) {
        frame->flags |= HAL_CAN_FLAG_EXTENDED;
        frame->id = (rir >> CAN_IR_EXID_SHIFT) & HAL_CAN_EXT_ID_MAX;
    } else {
        frame->id = (rir >> CAN_IR_STID_SHIFT) & HAL_CAN_STD_ID_MAX;
    }
    if (rir & CAN_IR_RTR) {
        frame->flags |= HAL_CAN_FLAG_REMOTE;
    }
    frame->dlc = (uint8_t)dlc;
    for (uint32_t i = 0; i < 4u; i++) {
        frame->data[i] = (uint8_t)(lo >> (8u * i));
        frame->data[4u + i] = (uint8_t)(hi >> (8u * i));
    }
    can->RF0R = CAN_RF0R_RFOM0 | clear;  // release the slot: the next frame moves to the output
    return true;
}

// ---- The port: interrupt handlers' work and counters ------------------------------------------

#define CAN_FIFO_DEPTH 3u

void stm32f4_can_rx_irq(stm32f4_can_port_t *p)
{
    for (uint32_t i = 0; i < CAN_FIFO_DEPTH; i++) {
        hal_can_frame_t frame;
        bool overrun = false;
        const bool got = stm32f4_can_read(p->regs, &frame, &overrun);
        if (overrun) {
            p->stats.rx_overruns++;  // at least one frame lost while the FIFO was full
        }
        if (!got) {
            return;
        }
        p->stats.rx_frames++;
        if (p->on_rx != NULL) {
            p->on_rx(&frame, p->ctx);
        }
        // The next frame is in the output mailbox only once the release is done.
        if (stm32f4_wait_bits(&p->regs->RF0R, CAN_RF0R_RFOM0, 0u, STM32F4_CFG_CAN_RELEASE_POLLS) !=
            FW_OK) {
            return;  // FMP0 is not 0: the interrupt comes back for the rest
        }
    }
}

void stm32f4_can_sce_irq(stm32f4_can_port_t *p)
{
    // Error warning, passive and bus-off transitions (ABOM recovers from bus-off by itself).
    if (p->regs->ESR & (CAN_ESR_EWGF | CAN_ESR_EPVF | CAN_ESR_BOFF)) {
        p->stats.bus_errors++;
    }
    p->regs->MSR = CAN_MSR_ERRI;  // write 1 to clear; the 0s leave the other flags as they are
}

int stm32f4_can_send(stm32f4_can_port_t *p, const hal_can_frame_t *frame)
{
    const int rc = stm32f4_can_write(p->regs, frame);
    if (rc >= 0) {
        p->stats.tx_frames++;
        return FW_OK;
    }
    if (rc == FW_ERR_FULL) {
        p->stats.tx_dropped++;
    }
    return rc;
}
