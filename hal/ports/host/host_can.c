// SPDX-License-Identifier: MIT
// dynaqpc host port: CAN. In lock-step, sent frames wait in a static ring the simulator drains;
// received frames come from hal_host_can_deliver(), which plays the receive interrupt. A
// transport (the virtual CAN bus) can take over sending; its receiver delivers the same way.
//
// The port's own lock (lock_) guards the queue, filter and counters and is never held while the
// irq mutex is taken or a handler runs, so a handler may send without deadlocking.
#include <pthread.h>
#include <string.h>

#include "fw/fw_base.h"
#include "hal/hal_can.h"
#include "hal/hal_cpu.h"
#include "hal_host/hal_host.h"
#include "host_internal.h"

static pthread_mutex_t lock_ = PTHREAD_MUTEX_INITIALIZER;
static bool ready_;
static uint32_t bitrate_;
static uint32_t filter_[FW_CFG_HOST_CAN_MAX_FILTER_IDS];
static uint32_t n_filter_;
static hal_can_rx_fn on_rx_;
static void *rx_ctx_;
static const hal_host_can_transport_t *transport_;
static hal_can_frame_t tx_[FW_CFG_HOST_CAN_TX_CAPACITY];
static uint32_t tx_head_; // next to take
static uint32_t tx_count_;
static hal_can_stats_t stats_;
// A stall in progress (hal_host_can_stall_begin()): the accepted frames FIFO 0 took so far, and
// the newest one, which the next arrival overwrites.
#define BXCAN_FIFO_DEPTH 3u
static bool stalled_;
static uint32_t stall_taken_;
static bool has_newest_;
static hal_can_frame_t newest_;
static uint32_t stall_lost_;

static bool frame_valid(const hal_can_frame_t *f)
{
    if ((f->flags & ~(uint32_t)(HAL_CAN_FLAG_EXTENDED | HAL_CAN_FLAG_REMOTE)) != 0u) {
        return false;
    }
    if (f->dlc > HAL_CAN_MAX_DLC) {
        return false;
    }
    uint32_t max_id = (f->flags & HAL_CAN_FLAG_EXTENDED) != 0u ? HAL_CAN_EXT_ID_MAX
                                                                 : HAL_CAN_STD_ID_MAX;
    return f->id <= max_id;
}

// Caller holds lock_.
static bool accepted_locked(const hal_can_frame_t *f)
{
    if (n_filter_ == 0u) {
        return true;
    }
    if ((f->flags & HAL_CAN_FLAG_EXTENDED) != 0u) {
        return false; // the list holds standard ids only
    }
    for (uint32_t i = 0; i < n_filter_; i++) {
        if (filter_[i] == f->id) {
            return true;
        }
    }
    return false;
}

void host_can_reset(void)
{
    pthread_mutex_lock(&lock_);
    ready_ = false;
    bitrate_ = 0;
    n_filter_ = 0;
    on_rx_ = NULL;
    rx_ctx_ = NULL;
    transport_ = NULL;
    tx_head_ = 0;
    tx_count_ = 0;
    memset(&stats_, 0, sizeof stats_);
    stalled_ = false;
    stall_taken_ = 0;
    has_newest_ = false;
    stall_lost_ = 0;
    pthread_mutex_unlock(&lock_);
}

int hal_can_init(uint32_t bitrate, const uint32_t *accept_ids, uint32_t n_ids, hal_can_rx_fn on_rx,
                 void *ctx)
{
    // The host has no bit timing to reach; it accepts the range bxCAN supports.
    if (bitrate < 10000u || bitrate > 1000000u || on_rx == NULL ||
        n_ids > (uint32_t)FW_CFG_HOST_CAN_MAX_FILTER_IDS || (n_ids > 0u && accept_ids == NULL)) {
        return FW_ERR_INVAL;
    }
    for (uint32_t i = 0; i < n_ids; i++) {
        if (accept_ids[i] > HAL_CAN_STD_ID_MAX) {
            return FW_ERR_INVAL;
        }
    }
    pthread_mutex_lock(&lock_);
    bitrate_ = bitrate;
    for (uint32_t i = 0; i < n_ids; i++) {
        filter_[i] = accept_ids[i];
    }
    n_filter_ = n_ids;
    on_rx_ = on_rx;
    rx_ctx_ = ctx;
    ready_ = true;
    pthread_mutex_unlock(&lock_);
    return FW_OK;
}

int hal_can_send(const hal_can_frame_t *frame)
{
    if (frame == NULL || !frame_valid(frame)) {
        return FW_ERR_INVAL;
    }
    pthread_mutex_lock(&lock_);
    if (!ready_) {
        pthread_mutex_unlock(&lock_);
        return FW_ERR_IO;
    }
    const hal_host_can_transport_t *tr = transport_;
    if (tr == NULL) {
        int rc = FW_OK;
        if (tx_count_ >= (uint32_t)FW_CFG_HOST_CAN_TX_CAPACITY) {
            stats_.tx_dropped++;
            rc = FW_ERR_FULL;
        } else {
            tx_[(tx_head_ + tx_count_) % (uint32_t)FW_CFG_HOST_CAN_TX_CAPACITY] = *frame;
            tx_count_++;
            stats_.tx_frames++;
        }
        pthread_mutex_unlock(&lock_);
        return rc;
    }
    pthread_mutex_unlock(&lock_);

    int rc = tr->send(frame, tr->ctx);
    pthread_mutex_lock(&lock_);
    if (rc == FW_OK) {
        stats_.tx_frames++;
    } else {
        stats_.tx_dropped++;
        rc = rc == FW_ERR_FULL ? FW_ERR_FULL : FW_ERR_IO;
    }
    pthread_mutex_unlock(&lock_);
    return rc;
}

void hal_can_get_stats(hal_can_stats_t *out)
{
    FW_ASSERT(out != NULL);
    pthread_mutex_lock(&lock_);
    *out = stats_;
    pthread_mutex_unlock(&lock_);
}

void hal_host_can_set_transport(const hal_host_can_transport_t *transport)
{
    pthread_mutex_lock(&lock_);
    transport_ = (transport != NULL && transport->send != NULL) ? transport : NULL;
    pthread_mutex_unlock(&lock_);
}

bool hal_host_can_take_tx(hal_can_frame_t *out)
{
    bool got = false;
    pthread_mutex_lock(&lock_);
    if (tx_count_ > 0u) {
        *out = tx_[tx_head_];
        tx_head_ = (tx_head_ + 1u) % (uint32_t)FW_CFG_HOST_CAN_TX_CAPACITY;
        tx_count_--;
        got = true;
    }
    pthread_mutex_unlock(&lock_);
    return got;
}

// What the controller does with an arriving frame before storing it: FW_OK for one its filters
// accept, FW_ERR_INVAL (a bus error, counted) or FW_ERR_NOENT (filtered out), FW_ERR_IO before
// hal_can_init(). Caller holds lock_.
static int admit_locked(const hal_can_frame_t *frame)
{
    if (!ready_) {
        return FW_ERR_IO;
    }
    if (!frame_valid(frame)) {
        stats_.bus_errors++;
        return FW_ERR_INVAL;
    }
    return accepted_locked(frame) ? FW_OK : FW_ERR_NOENT;
}

// admit_locked() for a caller without the lock: on FW_OK it returns holding lock_.
static int admit_and_lock(const hal_can_frame_t *frame)
{
    if (frame == NULL) {
        return FW_ERR_INVAL;
    }
    pthread_mutex_lock(&lock_);
    const int admitted = admit_locked(frame);
    if (admitted != FW_OK) {
        pthread_mutex_unlock(&lock_);
    }
    return admitted;
}

// Hands an admitted frame to the rx handler as the interrupt would, and wakes the CPU. Called
// with lock_ held; releases it before the handler runs.
static int hand_over_unlock(const hal_can_frame_t *frame)
{
    hal_can_rx_fn fn = on_rx_;
    void *ctx = rx_ctx_;
    stats_.rx_frames++;
    pthread_mutex_unlock(&lock_);

    // The handler gets a copy with the unused data bytes zeroed, as the controller's FIFO
    // registers would read, so nothing of the caller's padding leaks into the firmware.
    hal_can_frame_t copy = *frame;
    uint8_t n = (copy.flags & HAL_CAN_FLAG_REMOTE) != 0u ? 0u : copy.dlc;
    memset(&copy.data[n], 0, HAL_CAN_MAX_DLC - n);

    hal_irq_state_t irq = hal_irq_save();
    fn(&copy, ctx);
    hal_irq_restore(irq);
    hal_host_cpu_wake();
    return FW_OK;
}

int hal_host_can_deliver(const hal_can_frame_t *frame)
{
    const int admitted = admit_and_lock(frame);
    if (admitted != FW_OK) {
        return admitted;
    }
    return hand_over_unlock(frame);
}

void hal_host_can_stall_begin(void)
{
    pthread_mutex_lock(&lock_);
    stalled_ = true;
    stall_taken_ = 0;
    has_newest_ = false;
    pthread_mutex_unlock(&lock_);
}

int hal_host_can_deliver_stalled(const hal_can_frame_t *frame)
{
    const int admitted = admit_and_lock(frame);
    if (admitted != FW_OK) {
        return admitted;
    }
    // The first mailboxes keep their frames; the last is overwritten by every later arrival
    // (MCR.RFLM = 0), which sets FOVR0.
    if (!stalled_ || stall_taken_ + 1u < BXCAN_FIFO_DEPTH) {
        stall_taken_ += stalled_ ? 1u : 0u;
        return hand_over_unlock(frame);
    }
    if (has_newest_) {
        stats_.rx_overruns++;
        stall_lost_++;
    }
    newest_ = *frame;
    has_newest_ = true;
    pthread_mutex_unlock(&lock_);
    return FW_OK;
}

void hal_host_can_stall_end(void)
{
    pthread_mutex_lock(&lock_);
    const bool deliver = stalled_ && has_newest_;
    stalled_ = false;
    has_newest_ = false;
    if (!deliver) {
        pthread_mutex_unlock(&lock_);
        return;
    }
    const hal_can_frame_t newest = newest_;  // admitted when it arrived
    (void)hand_over_unlock(&newest);
}

uint32_t hal_host_can_stall_lost(void)
{
    return host_locked_u32(&lock_, &stall_lost_);
}

void hal_host_can_count_rx_overrun(uint32_t frames)
{
    pthread_mutex_lock(&lock_);
    stats_.rx_overruns += frames;
    pthread_mutex_unlock(&lock_);
}

uint32_t hal_host_can_bitrate(void)
{
    return host_locked_u32(&lock_, &bitrate_);
}
