// SPDX-License-Identifier: MIT
// dynaqpc host port: the flash region, as NOR flash behaves, in a static RAM image that can be
// written through to a file, with a power-cut injector for the persistence layer's tests.
//
// A write programs byte by byte in address order, as the MCU's flash interface does word by
// word: that is what makes "the bytes before the cut are programmed, the rest are not" exact.
// A byte that would need a 0 -> 1 transition gets what NOR physically gives (old & new) and the
// write reports FW_ERR_IO, like the MCU's verify after programming.
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "fw/fw_base.h"
#include "hal/hal_flash.h"
#include "hal_host/hal_host.h"
#include "host_internal.h"

static pthread_mutex_t lock_ = PTHREAD_MUTEX_INITIALIZER;
// Word-aligned: hal_flash_map() hands out pointers the firmware reads words through.
static uint8_t image_[FW_CFG_HOST_FLASH_CAPACITY] __attribute__((aligned(16)));
static bool image_ready_; // the image starts erased; static storage starts at 0
static hal_flash_geometry_t geo_ = {FW_CFG_HOST_FLASH_SECTOR_SIZE, FW_CFG_HOST_FLASH_SECTOR_COUNT,
                                    FW_CFG_HOST_FLASH_WRITE_ALIGN};
static int fd_ = -1;
static bool cut_armed_;
static uint32_t cut_left_;  // bytes still programmable before the cut
static bool power_off_;
static bool erase_cut_armed_;
static uint32_t erase_cut_skip_;   // complete erases still to go before the cut one
static uint32_t erase_cut_bytes_;  // bytes of the cut erase that are erased
static uint64_t programmed_;
static uint32_t erases_;

static uint32_t region_size(void)
{
    return geo_.sector_size * geo_.sector_count;
}

// Caller holds lock_.
static void ensure_image_locked(void)
{
    if (!image_ready_) {
        memset(image_, 0xFF, sizeof image_);
        image_ready_ = true;
    }
}

static bool range_ok(uint32_t offset, size_t len)
{
    uint32_t size = region_size();
    return offset <= size && len <= (size_t)(size - offset);
}

// Writes image_[offset, offset+len) through to the file. Caller holds lock_.
static int write_through_locked(uint32_t offset, size_t len)
{
    if (fd_ < 0 || len == 0u) {
        return FW_OK;
    }
    size_t done = 0;
    while (done < len) {
        ssize_t w = pwrite(fd_, &image_[offset + done], len - done, (off_t)(offset + done));
        if (w < 0 && errno == EINTR) {
            continue;
        }
        if (w <= 0) {
            return FW_ERR_IO;
        }
        done += (size_t)w;
    }
    return FW_OK;
}

int hal_flash_get_geometry(hal_flash_geometry_t *out)
{
    if (out == NULL) {
        return FW_ERR_INVAL;
    }
    pthread_mutex_lock(&lock_);
    *out = geo_;
    pthread_mutex_unlock(&lock_);
    return FW_OK;
}

int hal_flash_read(uint32_t offset, void *buf, size_t len)
{
    if (buf == NULL && len != 0u) {
        return FW_ERR_INVAL;
    }
    pthread_mutex_lock(&lock_);
    ensure_image_locked();
    int rc = FW_ERR_INVAL;
    if (range_ok(offset, len)) {
        if (len != 0u) {
            memcpy(buf, &image_[offset], len);
        }
        rc = FW_OK;
    }
    pthread_mutex_unlock(&lock_);
    return rc;
}

const void *hal_flash_map(uint32_t offset, size_t len)
{
    pthread_mutex_lock(&lock_);
    ensure_image_locked();
    const void *p = range_ok(offset, len) ? &image_[offset] : NULL;
    pthread_mutex_unlock(&lock_);
    return p;
}

int hal_flash_erase(uint32_t sector)
{
    pthread_mutex_lock(&lock_);
    ensure_image_locked();
    int rc;
    if (sector >= geo_.sector_count) {
        rc = FW_ERR_INVAL;
    } else if (power_off_) {
        rc = FW_ERR_IO;
    } else {
        uint32_t start = sector * geo_.sector_size;
        uint32_t n = geo_.sector_size;
        bool cut = false;
        if (erase_cut_armed_) {
            if (erase_cut_skip_ > 0u) {
                erase_cut_skip_--;
            } else {
                cut = true;
                n = erase_cut_bytes_ < n ? erase_cut_bytes_ : n;
            }
        }
        memset(&image_[start], 0xFF, n);
        erases_++;
        rc = write_through_locked(start, n);
        if (cut) {
            erase_cut_armed_ = false;
            power_off_ = true;
            rc = FW_ERR_IO;
        }
    }
    pthread_mutex_unlock(&lock_);
    return rc;
}

int hal_flash_write(uint32_t offset, const void *data, size_t len)
{
    if (data == NULL && len != 0u) {
        return FW_ERR_INVAL;
    }
    pthread_mutex_lock(&lock_);
    ensure_image_locked();
    int rc = FW_OK;
    if (offset % geo_.write_align != 0u || len % geo_.write_align != 0u || !range_ok(offset, len)) {
        rc = FW_ERR_INVAL;
    } else if (power_off_) {
        rc = FW_ERR_IO;
    } else {
        const uint8_t *src = data;
        size_t n = len;
        if (cut_armed_ && n > cut_left_) {
            n = cut_left_;
            rc = FW_ERR_IO;
        }
        // Eight bytes a step, without a branch: a save programs tens of KB, and under the fuzz
        // preset's sanitizers every byte access was checked on its own.
        uint64_t lost = 0; // bits asked as 1 where only a 0 can be
        size_t i = 0;
        for (; i + 8u <= n; i += 8u) {
            uint64_t old, want;
            memcpy(&old, &image_[offset + i], 8);
            memcpy(&want, &src[i], 8);
            const uint64_t now = old & want;
            lost |= now ^ want;
            memcpy(&image_[offset + i], &now, 8);
        }
        for (; i < n; i++) {
            const uint8_t now = (uint8_t)(image_[offset + i] & src[i]);
            lost |= (uint8_t)(now ^ src[i]);
            image_[offset + i] = now;
        }
        if (lost != 0u) {
            rc = FW_ERR_IO; // verify fails
        }
        programmed_ += n;
        if (cut_armed_) {
            cut_left_ -= (uint32_t)n;
            if (cut_left_ == 0u) {
                power_off_ = true;
            }
        }
        int wr = write_through_locked(offset, n);
        if (rc == FW_OK) {
            rc = wr;
        }
    }
    pthread_mutex_unlock(&lock_);
    return rc;
}

int hal_host_flash_configure(uint32_t sector_size, uint32_t sector_count, uint32_t write_align)
{
    if (sector_count < 2u || sector_size == 0u || !FW_IS_POW2(write_align) ||
        sector_size % write_align != 0u ||
        (uint64_t)sector_size * sector_count > (uint64_t)FW_CFG_HOST_FLASH_CAPACITY) {
        return FW_ERR_INVAL;
    }
    hal_host_flash_detach_file();
    pthread_mutex_lock(&lock_);
    geo_.sector_size = sector_size;
    geo_.sector_count = sector_count;
    geo_.write_align = write_align;
    // The region only: nothing past it can be read or written until a configure erases it. A
    // fuzz input configures a small flash every time (the host image is 512 KB).
    memset(image_, 0xFF, (size_t)sector_size * sector_count);
    image_ready_ = true;
    pthread_mutex_unlock(&lock_);
    return FW_OK;
}

// Reads a whole region image from fd into the image. The image changes only once the whole file
// has been read: a short read, or a file of another size, loses nothing.
static int read_image_locked(int fd, uint32_t size)
{
    static uint8_t staging[FW_CFG_HOST_FLASH_CAPACITY];
    size_t done = 0;
    while (done < size) {
        ssize_t r = pread(fd, &staging[done], size - done, (off_t)done);
        if (r < 0 && errno == EINTR) {
            continue;
        }
        if (r <= 0) {
            return FW_ERR_IO;
        }
        done += (size_t)r;
    }
    memcpy(image_, staging, size);
    return FW_OK;
}

// Opens path as the region's file and brings the image up to it: a file of the region's size is
// read into the image (read_image_locked: all or nothing); with `attach`, a new (empty) file is
// made a copy of the image instead, and the open file backs the region from then on; without, the
// file is only read and closed. Returns FW_OK, FW_ERR_CORRUPT (another size), FW_ERR_IO or
// FW_ERR_INVAL (NULL); on an error the image is as it was and no file stays open.
static int use_file_(const char *path, bool attach)
{
    if (path == NULL) {
        return FW_ERR_INVAL;
    }
    hal_host_flash_detach_file();
    pthread_mutex_lock(&lock_);
    ensure_image_locked();
    const uint32_t size = region_size();
    int rc;
    const int fd = attach ? open(path, O_RDWR | O_CREAT, 0644) : open(path, O_RDONLY);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0) {
        rc = FW_ERR_IO;
    } else if (attach && st.st_size == 0) {
        // A new file: it starts as a copy of the image.
        fd_ = fd;
        rc = write_through_locked(0, size);
        fd_ = -1;
    } else if (st.st_size != (off_t)size) {
        rc = FW_ERR_CORRUPT;
    } else {
        rc = read_image_locked(fd, size);
    }
    if (rc == FW_OK && attach) {
        fd_ = fd;
    } else if (fd >= 0) {
        close(fd);
    }
    pthread_mutex_unlock(&lock_);
    return rc;
}

int hal_host_flash_attach_file(const char *path)
{
    return use_file_(path, true);
}

int hal_host_flash_load_file(const char *path)
{
    return use_file_(path, false);
}

void hal_host_flash_detach_file(void)
{
    pthread_mutex_lock(&lock_);
    if (fd_ >= 0) {
        close(fd_);
        fd_ = -1;
    }
    pthread_mutex_unlock(&lock_);
}

void hal_host_flash_cut_power_after(uint32_t bytes)
{
    pthread_mutex_lock(&lock_);
    cut_armed_ = true;
    cut_left_ = bytes;
    power_off_ = bytes == 0u;
    pthread_mutex_unlock(&lock_);
}

void hal_host_flash_cut_power_in_erase(uint32_t erases, uint32_t bytes)
{
    pthread_mutex_lock(&lock_);
    erase_cut_armed_ = true;
    erase_cut_skip_ = erases;
    erase_cut_bytes_ = bytes;
    pthread_mutex_unlock(&lock_);
}

// The power back on and no cut armed (of a write or of an erase).
static void power_on_locked(void)
{
    erase_cut_armed_ = false;
    cut_armed_ = false;
    cut_left_ = 0;
    power_off_ = false;
}

void hal_host_flash_restore_power(void)
{
    pthread_mutex_lock(&lock_);
    power_on_locked();
    pthread_mutex_unlock(&lock_);
}

uint64_t hal_host_flash_programmed_bytes(void)
{
    return host_locked_u64(&lock_, &programmed_);
}

uint32_t hal_host_flash_erase_count(void)
{
    return host_locked_u32(&lock_, &erases_);
}

void host_flash_reset(void)
{
    pthread_mutex_lock(&lock_);
    power_on_locked();
    programmed_ = 0;
    erases_ = 0;
    pthread_mutex_unlock(&lock_);
}
