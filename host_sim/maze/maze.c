// SPDX-License-Identifier: MIT
// dynaqpc: the gridworld. No allocation, no I/O: the caller reads the file, this checks the text.
#include "maze/maze.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

// ---- Errors -------------------------------------------------------------------------------------

#if defined(__GNUC__)
__attribute__((format(printf, 5, 6)))
#endif
static int fail_(maze_error_t *err, const char *file, int line, int column, const char *fmt, ...)
{
    va_list ap;
    if (err == NULL) {
        return -1;
    }
    err->line = line;
    err->column = column;
    va_start(ap, fmt);
    (void)vsnprintf(err->what, sizeof err->what, fmt, ap);
    va_end(ap);
    (void)snprintf(err->message, sizeof err->message, "%s:%d:%d: %s",
                   file != NULL ? file : "<map>", line, column, err->what);
    return -1;
}

// A byte as it should appear inside quotes in a one-line message: itself when printable,
// otherwise an escape, so that binary garbage never puts control characters on the terminal.
static void quote_byte_(unsigned char c, char out[8])
{
    switch (c) {
    case '\t': (void)strcpy(out, "\\t"); break;
    case '\r': (void)strcpy(out, "\\r"); break;
    case '\0': (void)strcpy(out, "\\0"); break;
    case '\\': (void)strcpy(out, "\\\\"); break;
    case '\'': (void)strcpy(out, "\\'"); break;
    default:
        if (c >= 0x20u && c < 0x7fu) {
            out[0] = (char)c;
            out[1] = '\0';
        } else {
            (void)snprintf(out, 8, "\\x%02x", (unsigned)c);
        }
        break;
    }
}

static int cell_of_(unsigned char c)
{
    switch (c) {
    case '.': return MAZE_FREE;
    case '#': return MAZE_WALL;
    case 'S': return MAZE_START;
    case 'G': return MAZE_GOAL;
    default: return -1;
    }
}

// ---- Shortest paths -----------------------------------------------------------------------------

// Breadth-first search from every goal at once. Moves are reversible (a move between two free
// neighbours works both ways; walls and edges only ever block), so the distance from the goals
// to a cell is the cell's shortest path to its nearest goal. A path never needs to pass through
// a goal: the first goal on it would be nearer.
static void shortest_paths_(maze_t *m)
{
    static const int dr[4] = {-1, 1, 0, 0};
    static const int dc[4] = {0, 0, -1, 1};
    uint16_t queue[MAZE_MAX_CELLS];
    uint32_t head = 0;
    uint32_t tail = 0;
    int r;
    int c;

    // Only the map's own cells: every read of dist is bounded by rows and cols.
    for (r = 0; r < m->rows; r++) {
        for (c = 0; c < m->cols; c++) {
            m->dist[r][c] = MAZE_UNREACHABLE;
        }
    }
    for (r = 0; r < m->rows; r++) {
        for (c = 0; c < m->cols; c++) {
            if (m->cell[r][c] == MAZE_GOAL) {
                m->dist[r][c] = 0;
                queue[tail++] = (uint16_t)(r * MAZE_MAX_COLS + c);
            }
        }
    }
    while (head < tail) {
        const int r0 = queue[head] / MAZE_MAX_COLS;
        const int c0 = queue[head] % MAZE_MAX_COLS;
        int k;
        head++;
        for (k = 0; k < 4; k++) {
            const int r1 = r0 + dr[k];
            const int c1 = c0 + dc[k];
            if (r1 < 0 || r1 >= m->rows || c1 < 0 || c1 >= m->cols) {
                continue;
            }
            if (m->cell[r1][c1] == MAZE_WALL || m->dist[r1][c1] != MAZE_UNREACHABLE) {
                continue;
            }
            m->dist[r1][c1] = (uint16_t)(m->dist[r0][c0] + 1u);
            queue[tail++] = (uint16_t)(r1 * MAZE_MAX_COLS + c1);
        }
    }
}

// The starts and goals of a map whose cells are set, and its shortest paths; every start must
// reach a goal.
static int index_cells_(maze_t *m, const char *file, maze_error_t *err)
{
    int r;
    int c;
    m->n_starts = 0;
    m->n_goals = 0;
    for (r = 0; r < m->rows; r++) {
        for (c = 0; c < m->cols; c++) {
            if (m->cell[r][c] == MAZE_START) {
                m->starts[m->n_starts].row = (uint8_t)r;
                m->starts[m->n_starts].col = (uint8_t)c;
                m->n_starts++;
            } else if (m->cell[r][c] == MAZE_GOAL) {
                m->n_goals++;
            }
        }
    }
    if (m->n_starts == 0) {
        return fail_(err, file, 1, 1, "no start cell 'S'");
    }
    if (m->n_goals == 0) {
        return fail_(err, file, 1, 1, "no goal cell 'G'");
    }
    shortest_paths_(m);
    for (r = 0; r < m->n_starts; r++) {
        const maze_pos_t s = m->starts[r];
        if (m->dist[s.row][s.col] == MAZE_UNREACHABLE) {
            // Rows are lines one to one: no empty line can come before a row.
            return fail_(err, file, s.row + 1, s.col + 1, "no goal is reachable from this start");
        }
    }
    return 0;
}

// ---- Parser -------------------------------------------------------------------------------------

int maze_parse(maze_t *m, const char *text, size_t len, const char *file, maze_error_t *err)
{
    size_t pos = 0;
    int line = 0;           // 1-based number of the line being read
    int first_empty = 0;    // first of a run of empty lines not yet followed by a row, or 0

    memset(m, 0, sizeof *m);
    if (err != NULL) {
        memset(err, 0, sizeof *err);
    }
    if (text == NULL || len == 0u) {
        return fail_(err, file, 1, 1, "empty file");
    }
    if (len > MAZE_MAX_FILE_BYTES) {
        return fail_(err, file, 1, 1, "file too large (more than %u bytes)",
                     (unsigned)MAZE_MAX_FILE_BYTES);
    }

    while (pos < len) {
        const unsigned char *row = (const unsigned char *)text + pos;
        size_t end = pos;
        size_t n;
        size_t i;

        line++;
        while (end < len && text[end] != '\n') {
            end++;
        }
        n = end - pos;
        pos = (end < len) ? end + 1u : end;  // past the '\n', if there is one
        if (n > 0u && row[n - 1u] == '\r') {
            n--;  // "\r\n"
        }

        if (n == 0u) {
            if (first_empty == 0) {
                first_empty = line;
            }
            continue;  // fine if only empty lines follow
        }
        if (first_empty != 0) {
            if (m->rows == 0) {
                return fail_(err, file, first_empty, 1, "empty line before the map");
            }
            return fail_(err, file, first_empty, 1,
                         "empty line inside the map (row has 0 columns, expected %u)",
                         (unsigned)m->cols);
        }
        if (m->rows == MAZE_MAX_ROWS) {
            return fail_(err, file, line, 1, "too many rows (at most %d)", MAZE_MAX_ROWS);
        }
        if (m->rows > 0 && (uint32_t)(m->rows + 1) * m->cols > MAZE_MAX_CELLS) {
            return fail_(err, file, line, 1, "too many cells: %d rows of %u columns (at most %d cells)",
                         m->rows + 1, (unsigned)m->cols, MAZE_MAX_CELLS);
        }
        for (i = 0; i < n; i++) {
            char shown[8];
            int cell;
            if (m->rows > 0 && i >= m->cols) {
                return fail_(err, file, line, (int)i + 1,
                             "ragged row: more than the %u columns of line 1", (unsigned)m->cols);
            }
            if (i >= MAZE_MAX_COLS) {
                return fail_(err, file, line, (int)i + 1, "row too long (at most %d columns)",
                             MAZE_MAX_COLS);
            }
            cell = cell_of_(row[i]);
            if (cell < 0) {
                quote_byte_(row[i], shown);
                return fail_(err, file, line, (int)i + 1,
                             "unknown character '%s' (expected '#', '.', 'S' or 'G')", shown);
            }
            m->cell[m->rows][i] = (uint8_t)cell;
        }
        if (m->rows == 0) {
            m->cols = (uint16_t)n;
        } else if (n < m->cols) {
            return fail_(err, file, line, (int)n + 1,
                         "ragged row: %u columns, expected %u as in line 1", (unsigned)n,
                         (unsigned)m->cols);
        }
        m->rows++;
    }

    if (m->rows == 0) {
        return fail_(err, file, 1, 1, "empty map (no rows)");
    }
    return index_cells_(m, file, err);
}

int maze_refine(maze_t *out, const maze_t *in, unsigned k, const char *file, maze_error_t *err)
{
    if (err != NULL) {
        memset(err, 0, sizeof *err);
    }
    if (k < 1u || k > MAZE_MAX_ROWS) {
        return fail_(err, file, 1, 1, "refinement %u: must be 1..%d", k, MAZE_MAX_ROWS);
    }
    const uint32_t rows = in->rows * k;
    const uint32_t cols = in->cols * k;
    if (rows > MAZE_MAX_ROWS || cols > MAZE_MAX_COLS || rows * cols > MAZE_MAX_CELLS) {
        return fail_(err, file, 1, 1,
                     "refined %u times the map is %u x %u cells (at most %d rows, %d columns and "
                     "%d cells)", k, (unsigned)rows, (unsigned)cols, MAZE_MAX_ROWS, MAZE_MAX_COLS,
                     MAZE_MAX_CELLS);
    }
    memset(out, 0, sizeof *out);
    out->rows = (uint16_t)rows;
    out->cols = (uint16_t)cols;
    for (uint32_t r = 0; r < rows; r++) {
        for (uint32_t c = 0; c < cols; c++) {
            const uint8_t cell = in->cell[r / k][c / k];
            // A start or a goal stays one cell, the block's first; the rest of its block is free.
            const bool first = r % k == 0u && c % k == 0u;
            out->cell[r][c] = cell == MAZE_WALL || first ? cell : (uint8_t)MAZE_FREE;
        }
    }
    return index_cells_(out, file, err);
}

// ---- Moves --------------------------------------------------------------------------------------

bool maze_move(const maze_t *m, maze_pos_t pos, uint8_t action, maze_pos_t *next)
{
    int r = pos.row;
    int c = pos.col;

    switch (action) {
    case MAZE_UP: r--; break;
    case MAZE_DOWN: r++; break;
    case MAZE_LEFT: c--; break;
    case MAZE_RIGHT: c++; break;
    default: break;  // not an action: stay
    }
    if (r < 0 || r >= m->rows || c < 0 || c >= m->cols || m->cell[r][c] == MAZE_WALL) {
        r = pos.row;
        c = pos.col;
    }
    next->row = (uint8_t)r;
    next->col = (uint8_t)c;
    return m->cell[r][c] == MAZE_GOAL;
}

bool maze_step(const maze_t *m, maze_pos_t pos, uint8_t action, float step_reward,
               float goal_reward, maze_pos_t *next, float *reward)
{
    const bool goal = maze_move(m, pos, action, next);
    *reward = goal ? goal_reward : step_reward;
    return goal;
}

bool maze_is_goal(const maze_t *m, maze_pos_t pos)
{
    return pos.row < m->rows && pos.col < m->cols && m->cell[pos.row][pos.col] == MAZE_GOAL;
}

uint16_t maze_shortest_from(const maze_t *m, maze_pos_t pos)
{
    if (pos.row >= m->rows || pos.col >= m->cols) {
        return MAZE_UNREACHABLE;
    }
    return m->dist[pos.row][pos.col];
}

uint16_t maze_shortest_max(const maze_t *m)
{
    uint16_t best = 0;
    uint16_t i;
    for (i = 0; i < m->n_starts; i++) {
        const uint16_t d = maze_shortest_from(m, m->starts[i]);
        if (d > best) {
            best = d;
        }
    }
    return best;
}

double maze_shortest_mean(const maze_t *m)
{
    double sum = 0.0;
    uint16_t i;
    if (m->n_starts == 0) {
        return 0.0;
    }
    for (i = 0; i < m->n_starts; i++) {
        sum += maze_shortest_from(m, m->starts[i]);
    }
    return sum / m->n_starts;
}

// ---- The agent's view ---------------------------------------------------------------------------

static uint8_t bits_for_(uint32_t n)
{
    uint8_t b = 1;
    while ((1u << b) < n) {
        b++;
    }
    return b;
}

uint8_t maze_row_bits(const maze_t *m)
{
    return bits_for_(m->rows);
}

uint8_t maze_col_bits(const maze_t *m)
{
    return bits_for_(m->cols);
}

void maze_space(const maze_t *m, agent_space_t *sp)
{
    memset(sp, 0, sizeof *sp);
    sp->n_components = 2;
    sp->bits[0] = maze_row_bits(m);
    sp->bits[1] = maze_col_bits(m);
    sp->tile_shift[0] = 0;
    sp->tile_shift[1] = 0;
    sp->circular_mask = 0;
    sp->absolute_mask = 0;
    sp->n_actions = MAZE_N_ACTIONS;
}

agent_state_t maze_state(const maze_t *m, maze_pos_t pos)
{
    return (agent_state_t)pos.row | ((agent_state_t)pos.col << maze_row_bits(m));
}
