// SPDX-License-Identifier: MIT
// Unit tests of the gridworld: the map parser and its errors, moves, shortest paths, the state
// encoding, and the experiment runner's rows and determinism.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "agent/agent.h"
#include "robot/agent_profiles.h"
#include "fw/fw_prng.h"
#include "agent/space.h"
#include "maze/maze.h"
#include "maze/maze_run.h"

// Sutton & Barto's Fig. 8.2.
static const char dyna_maze_[] = ".......#G\n"
                                 "..#....#.\n"
                                 "S.#....#.\n"
                                 "..#......\n"
                                 ".....#...\n"
                                 ".........\n";

// maze_t is ~225 KB: static, not on the stack.
static maze_t maze_;
static maze_t maze2_;
static maze_error_t err_;

static int parse_(const char *text)
{
    return maze_parse(&maze_, text, strlen(text), "maps/x.txt", &err_);
}

static maze_pos_t pos_(int row, int col)
{
    maze_pos_t p;
    p.row = (uint8_t)row;
    p.col = (uint8_t)col;
    return p;
}

static void assert_error_at_(const char *text, int line, int column, const char *what)
{
    assert_int_equal(parse_(text), -1);
    assert_int_equal(err_.line, line);
    assert_int_equal(err_.column, column);
    if (what != NULL && strstr(err_.what, what) == NULL) {
        fail_msg("expected \"%s\" in \"%s\"", what, err_.what);
    }
}

// ---- Parsing ------------------------------------------------------------------------------------

static void test_parse_dyna_maze(void **state)
{
    static const int walls[7][2] = {{1, 2}, {2, 2}, {3, 2}, {0, 7}, {1, 7}, {2, 7}, {4, 5}};
    int r;
    int c;
    int n_walls = 0;
    (void)state;

    assert_int_equal(parse_(dyna_maze_), 0);
    assert_int_equal(maze_.rows, 6);
    assert_int_equal(maze_.cols, 9);
    assert_int_equal(maze_.n_starts, 1);
    assert_int_equal(maze_.starts[0].row, 2);
    assert_int_equal(maze_.starts[0].col, 0);
    assert_int_equal(maze_.n_goals, 1);
    assert_int_equal(maze_.cell[0][8], MAZE_GOAL);
    for (r = 0; r < 7; r++) {
        assert_int_equal(maze_.cell[walls[r][0]][walls[r][1]], MAZE_WALL);
    }
    for (r = 0; r < maze_.rows; r++) {
        for (c = 0; c < maze_.cols; c++) {
            n_walls += maze_.cell[r][c] == MAZE_WALL;
        }
    }
    assert_int_equal(n_walls, 7);
    assert_int_equal(maze_shortest_from(&maze_, maze_.starts[0]), 14);
    assert_int_equal(maze_shortest_max(&maze_), 14);
    assert_true(maze_shortest_mean(&maze_) == 14.0);
    assert_int_equal(maze_shortest_from(&maze_, pos_(0, 8)), 0);
    assert_int_equal(maze_shortest_from(&maze_, pos_(1, 2)), MAZE_UNREACHABLE);
}

static void test_crlf_and_trailing_lines_accepted(void **state)
{
    static const char crlf[] = ".......#G\r\n..#....#.\r\nS.#....#.\r\n..#......\r\n"
                               ".....#...\r\n.........\r\n\r\n\r\n";
    static const char no_final_newline[] = ".......#G\n..#....#.\nS.#....#.\n..#......\n"
                                           ".....#...\n.........";
    static const char trailing_empty[] = ".......#G\n..#....#.\nS.#....#.\n..#......\n"
                                         ".....#...\n.........\n\n\n\n";
    (void)state;

    assert_int_equal(maze_parse(&maze2_, dyna_maze_, strlen(dyna_maze_), "a", &err_), 0);
    assert_int_equal(parse_(crlf), 0);
    assert_memory_equal(&maze_, &maze2_, sizeof maze_);
    assert_int_equal(parse_(no_final_newline), 0);
    assert_memory_equal(&maze_, &maze2_, sizeof maze_);
    assert_int_equal(parse_(trailing_empty), 0);
    assert_memory_equal(&maze_, &maze2_, sizeof maze_);
    // Mixed endings are fine too; a lone '\r' is not a line ending.
    assert_int_equal(parse_("S.\r\n.G\n"), 0);
    assert_error_at_("S.\r.G\n", 1, 3, "unknown character '\\r'");
}

static void test_several_starts_and_goals(void **state)
{
    (void)state;
    assert_int_equal(parse_("S...G\n.###.\nS...G\n"), 0);
    assert_int_equal(maze_.n_starts, 2);
    assert_int_equal(maze_.n_goals, 2);
    assert_int_equal(maze_.starts[1].row, 2);
    assert_int_equal(maze_.starts[1].col, 0);
    assert_int_equal(maze_shortest_from(&maze_, maze_.starts[0]), 4);
    assert_int_equal(maze_shortest_max(&maze_), 4);
    // Nearest goal: the middle of the left column is 5 from either goal.
    assert_int_equal(maze_shortest_from(&maze_, pos_(1, 0)), 5);

    assert_int_equal(parse_("S....\n.###.\nS..#G\n"), 0);
    assert_int_equal(maze_shortest_from(&maze_, maze_.starts[0]), 6);
    assert_int_equal(maze_shortest_from(&maze_, maze_.starts[1]), 8);
    assert_int_equal(maze_shortest_max(&maze_), 8);
    assert_true(maze_shortest_mean(&maze_) == 7.0);
}

// ---- Map errors ---------------------------------------------------------------------------------

static void test_error_no_start_no_goal(void **state)
{
    (void)state;
    assert_error_at_("...\n..G\n", 1, 1, "no start");
    assert_error_at_("S..\n...\n", 1, 1, "no goal");
    assert_string_equal(err_.message, "maps/x.txt:1:1: no goal cell 'G'");
}

static void test_error_ragged_rows(void **state)
{
    (void)state;
    // Short row: the column after its last character.
    assert_error_at_("S..\n..\n..G\n", 2, 3, "ragged");
    // Long row: the first column past line 1's width.
    assert_error_at_("S..\n..G\n....\n", 3, 4, "ragged");
    // An empty line inside the map.
    assert_error_at_("S..\n\n..G\n", 2, 1, "empty line");
    assert_error_at_("\nS..\n..G\n", 1, 1, "empty line");
}

static void test_error_unknown_character(void **state)
{
    (void)state;
    assert_error_at_("S........\n.........\n......x..\n........G\n", 3, 7,
                     "unknown character 'x'");
    assert_true(strncmp(err_.message, "maps/x.txt:3:7: unknown character 'x'", 37) == 0);
    assert_error_at_("S. G\n", 1, 3, "unknown character ' '");
    assert_error_at_("S.\t.G\n", 1, 3, "'\\t'");
    assert_error_at_("S.G\n.\xc3\xa9.\n", 2, 2, "'\\xc3'");
}

static void test_error_unreachable_goal(void **state)
{
    (void)state;
    assert_error_at_("S#G\n", 1, 1, "no goal is reachable");
    assert_string_equal(err_.message, "maps/x.txt:1:1: no goal is reachable from this start");
    // The second start is walled off: its cell is named.
    assert_error_at_("S.G\n###\n.S.\n", 3, 2, "no goal is reachable");
}

static void test_error_empty(void **state)
{
    (void)state;
    assert_int_equal(maze_parse(&maze_, NULL, 0, "e.txt", &err_), -1);
    assert_int_equal(maze_parse(&maze_, "", 0, "e.txt", &err_), -1);
    assert_string_equal(err_.message, "e.txt:1:1: empty file");
    assert_error_at_("\n", 1, 1, "empty map");
    assert_error_at_("\r\n\n\r\n", 1, 1, "empty map");
}

// An open map of rows x cols into text: 'S' at the top left, 'G' at the bottom right. Returns
// its length.
static size_t open_map_(char *text, int rows, int cols)
{
    size_t n = 0;
    for (int r = 0; r < rows; r++) {
        memset(text + n, '.', (size_t)cols);
        if (r == 0) {
            text[n] = 'S';
        }
        if (r == rows - 1) {
            text[n + (size_t)cols - 1u] = 'G';
        }
        text[n + (size_t)cols] = '\n';
        n += (size_t)cols + 1u;
    }
    return n;
}

static void test_error_limits(void **state)
{
    static char big[MAZE_MAX_FILE_BYTES + 1u];
    static char text[MAZE_MAX_FILE_BYTES];
    size_t n = 0;
    int r;
    (void)state;

    // Too large, whatever it holds.
    memset(big, '.', sizeof big);
    assert_int_equal(maze_parse(&maze_, big, sizeof big, "big", &err_), -1);
    assert_int_equal(err_.line, 1);
    assert_int_equal(err_.column, 1);
    assert_non_null(strstr(err_.what, "too large"));
    // A long line is refused at the first column past the limit.
    assert_int_equal(maze_parse(&maze_, big, sizeof big - 1u, "big", &err_), -1);
    assert_int_equal(err_.line, 1);
    assert_int_equal(err_.column, MAZE_MAX_COLS + 1);
    // Too many rows.
    for (r = 0; r < MAZE_MAX_ROWS + 1; r++) {
        memcpy(text + n, "SG\n", 3);
        n += 3;
    }
    assert_int_equal(maze_parse(&maze_, text, n, "tall", &err_), -1);
    assert_int_equal(err_.line, MAZE_MAX_ROWS + 1);
    assert_int_equal(err_.column, 1);
    // Too many cells: 128 columns allow 128 rows.
    n = open_map_(text, 129, 128);
    assert_int_equal(maze_parse(&maze_, text, n, "wide", &err_), -1);
    assert_int_equal(err_.line, 129);
    assert_int_equal(err_.column, 1);
    assert_non_null(strstr(err_.what, "too many cells"));
    // The largest maps are fine: 128 x 128, and the most state bits (129 x 127: 8 + 7), which
    // still fit the maze profile's dense Q store.
    n = open_map_(text, 128, 128);
    assert_int_equal(maze_parse(&maze_, text, n, "square", &err_), 0);
    assert_int_equal(maze_shortest_max(&maze_), 2 * 127);
    n = open_map_(text, 129, 127);
    assert_int_equal(maze_parse(&maze_, text, n, "max", &err_), 0);
    assert_int_equal(maze_shortest_max(&maze_), 128 + 126);
    assert_int_equal(maze_row_bits(&maze_) + maze_col_bits(&maze_), 15);
    assert_true((1u << 15) <= FW_CFG_MAZE_Q_STATES);
    // One row as wide as a row can be.
    n = open_map_(text, 1, MAZE_MAX_COLS);
    assert_int_equal(maze_parse(&maze_, text, n, "long", &err_), 0);
    assert_int_equal(maze_shortest_max(&maze_), MAZE_MAX_COLS - 1);
}

// Refining keeps walls as blocks and a start or a goal as one cell: the Dyna maze at 2 x has its
// path twice as long, and its start where the start's block begins.
static void test_refine(void **state)
{
    (void)state;
    assert_int_equal(maze_parse(&maze_, dyna_maze_, strlen(dyna_maze_), "dyna", &err_), 0);
    assert_int_equal(maze_refine(&maze2_, &maze_, 2, "dyna", &err_), 0);
    assert_int_equal(maze2_.rows, 12);
    assert_int_equal(maze2_.cols, 18);
    assert_int_equal(maze2_.n_starts, 1);
    assert_int_equal(maze2_.n_goals, 1);
    assert_int_equal(maze2_.starts[0].row, 2 * maze_.starts[0].row);
    assert_int_equal(maze2_.starts[0].col, 2 * maze_.starts[0].col);
    assert_int_equal(maze_shortest_max(&maze2_), 2 * maze_shortest_max(&maze_));
    for (int r = 0; r < maze2_.rows; r++) {
        for (int c = 0; c < maze2_.cols; c++) {
            assert_int_equal(maze2_.cell[r][c] == MAZE_WALL, maze_.cell[r / 2][c / 2] == MAZE_WALL);
        }
    }
    // 1 copies; 0 and past the limits are refused with a reason, at 1:1.
    assert_int_equal(maze_refine(&maze2_, &maze_, 1, "dyna", &err_), 0);
    assert_int_equal(maze_shortest_max(&maze2_), maze_shortest_max(&maze_));
    assert_int_equal(maze_refine(&maze2_, &maze_, 0, "dyna", &err_), -1);
    assert_non_null(strstr(err_.message, "dyna:1:1: refinement 0"));
    assert_int_equal(maze_refine(&maze2_, &maze_, 17, "dyna", &err_), 0);  // 15,606 cells
    assert_int_equal(maze2_.rows * maze2_.cols, 102 * 153);
    assert_int_equal(maze_refine(&maze2_, &maze_, 18, "dyna", &err_), -1);  // 17,496 cells
    assert_non_null(strstr(err_.what, "108 x 162 cells"));
}

// Binary garbage: never a crash, a hang or an out-of-bounds access (the asan build checks the
// last), always one printable line with a position.
static void test_error_garbage(void **state)
{
    static char buf[4096];
    prng_t rng;
    int i;
    (void)state;

    memcpy(buf, "S.\0G\n", 5);
    assert_int_equal(maze_parse(&maze_, buf, 5, "nul", &err_), -1);
    assert_int_equal(err_.line, 1);
    assert_int_equal(err_.column, 3);
    assert_non_null(strstr(err_.what, "'\\0'"));

    prng_seed(&rng, 7);
    for (i = 0; i < 2000; i++) {
        const size_t len = 1u + prng_below(&rng, sizeof buf);
        const uint32_t alphabet = prng_below(&rng, 3);  // bytes, map-like, or mostly newlines
        size_t k;
        const char *m;
        int rc;
        for (k = 0; k < len; k++) {
            static const char mapish[] = "..##SG\n\r";
            if (alphabet == 0) {
                buf[k] = (char)prng_below(&rng, 256);
            } else if (alphabet == 1) {
                buf[k] = mapish[prng_below(&rng, 8)];
            } else {
                buf[k] = prng_below(&rng, 4) == 0 ? '.' : '\n';
            }
        }
        rc = maze_parse(&maze_, buf, len, "garbage.bin", &err_);
        if (rc == 0) {
            assert_true(maze_.rows >= 1 && maze_.rows <= MAZE_MAX_ROWS);
            assert_true(maze_.n_starts >= 1 && maze_.n_goals >= 1);
            continue;
        }
        assert_true(err_.line >= 1);
        assert_true(err_.column >= 1 && err_.column <= MAZE_MAX_COLS + 1);
        assert_true(strncmp(err_.message, "garbage.bin:", 12) == 0);
        for (m = err_.message; *m != '\0'; m++) {
            assert_true((unsigned char)*m >= 0x20u && (unsigned char)*m < 0x7fu);
        }
    }
}

// ---- Moves and rewards --------------------------------------------------------------------------

static void test_moves(void **state)
{
    maze_pos_t next;
    float r = -99.0f;
    (void)state;
    assert_int_equal(parse_(dyna_maze_), 0);

    // Free cells.
    assert_false(maze_step(&maze_, pos_(2, 0), MAZE_UP, 0.0f, 1.0f, &next, &r));
    assert_int_equal(next.row, 1);
    assert_int_equal(next.col, 0);
    assert_true(r == 0.0f);
    assert_false(maze_move(&maze_, pos_(2, 0), MAZE_DOWN, &next));
    assert_int_equal(next.row, 3);
    assert_false(maze_move(&maze_, pos_(2, 0), MAZE_RIGHT, &next));
    assert_int_equal(next.col, 1);
    // Edges leave the agent in place.
    assert_false(maze_move(&maze_, pos_(2, 0), MAZE_LEFT, &next));
    assert_int_equal(next.row, 2);
    assert_int_equal(next.col, 0);
    assert_false(maze_move(&maze_, pos_(0, 0), MAZE_UP, &next));
    assert_int_equal(next.row, 0);
    assert_int_equal(next.col, 0);
    assert_false(maze_move(&maze_, pos_(5, 8), MAZE_DOWN, &next));
    assert_int_equal(next.row, 5);
    assert_false(maze_move(&maze_, pos_(5, 8), MAZE_RIGHT, &next));
    assert_int_equal(next.col, 8);
    // So do walls.
    assert_false(maze_step(&maze_, pos_(2, 1), MAZE_RIGHT, -1.0f, 10.0f, &next, &r));
    assert_int_equal(next.row, 2);
    assert_int_equal(next.col, 1);
    assert_true(r == -1.0f);
    assert_false(maze_move(&maze_, pos_(3, 5), MAZE_DOWN, &next));
    assert_int_equal(next.row, 3);
    assert_int_equal(next.col, 5);
    // The goal is terminal and pays the goal reward.
    assert_true(maze_step(&maze_, pos_(1, 8), MAZE_UP, -1.0f, 10.0f, &next, &r));
    assert_int_equal(next.row, 0);
    assert_int_equal(next.col, 8);
    assert_true(r == 10.0f);
    assert_true(maze_is_goal(&maze_, next));
    assert_false(maze_is_goal(&maze_, pos_(1, 8)));
}

static void test_state_encoding(void **state)
{
    agent_space_t sp;
    uint32_t comp[FW_CFG_MAX_COMPONENTS];
    int r;
    int c;
    (void)state;

    assert_int_equal(parse_(dyna_maze_), 0);
    maze_space(&maze_, &sp);
    assert_int_equal(sp.n_components, 2);
    assert_int_equal(sp.bits[0], 3);  // 6 rows
    assert_int_equal(sp.bits[1], 4);  // 9 columns
    assert_int_equal(sp.tile_shift[0], 0);
    assert_int_equal(sp.tile_shift[1], 0);
    assert_int_equal(sp.circular_mask, 0);
    assert_int_equal(sp.absolute_mask, 0);
    assert_int_equal(sp.n_actions, 4);
    assert_int_equal(space_validate(&sp), 0);
    for (r = 0; r < maze_.rows; r++) {
        for (c = 0; c < maze_.cols; c++) {
            comp[0] = (uint32_t)r;
            comp[1] = (uint32_t)c;
            assert_int_equal(maze_state(&maze_, pos_(r, c)), space_pack(&sp, comp));
        }
    }
    // One row, two columns: still one bit each.
    assert_int_equal(parse_("SG\n"), 0);
    assert_int_equal(maze_row_bits(&maze_), 1);
    assert_int_equal(maze_col_bits(&maze_), 1);
    assert_int_equal(parse_("S.......G\n"), 0);
    assert_int_equal(maze_col_bits(&maze_), 4);
}

// ---- The runner ---------------------------------------------------------------------------------

#define MAX_ROWS 64

typedef struct rows {
    maze_episode_row_t episode[MAX_ROWS];
    maze_run_row_t run[MAX_ROWS];
    int n_episode;
    int n_run;
} rows_t;

static void on_episode_(void *ctx, const maze_episode_row_t *row)
{
    rows_t *rows = ctx;
    assert_true(rows->n_episode < MAX_ROWS);
    rows->episode[rows->n_episode++] = *row;
}

static void on_run_(void *ctx, const maze_run_row_t *row)
{
    rows_t *rows = ctx;
    assert_true(rows->n_run < MAX_ROWS);
    rows->run[rows->n_run++] = *row;
}

static double fake_clock_(void *ctx)
{
    static double t = 0.0;
    (void)ctx;
    t += 0.5;
    return t;
}

static maze_run_config_t config_(agent_kind_t kind, rows_t *rows)
{
    maze_run_config_t cfg = maze_run_default_config();
    cfg.maze = &maze_;
    cfg.kind = kind;
    cfg.runs = 3;
    cfg.episodes = 4;
    cfg.seed = 42;
    cfg.on_episode = on_episode_;
    cfg.on_run = on_run_;
    cfg.ctx = rows;
    memset(rows, 0, sizeof *rows);
    return cfg;
}

static void test_runner_rows_and_determinism(void **state)
{
    static rows_t a;
    static rows_t b;
    static const agent_kind_t kinds[3] = {AGENT_Q_LEARNING, AGENT_DYNA_Q, AGENT_DYNA_QPC};
    int k;
    int i;
    (void)state;

    assert_int_equal(parse_(dyna_maze_), 0);
    for (k = 0; k < 3; k++) {
        maze_run_config_t cfg = config_(kinds[k], &a);
        const char *why = NULL;
        assert_int_equal(maze_run(&cfg, &why), 0);
        cfg = config_(kinds[k], &b);
        cfg.clock = fake_clock_;  // the clock must not change anything but wall_s
        assert_int_equal(maze_run(&cfg, &why), 0);

        assert_int_equal(a.n_episode, 3 * 4);
        assert_int_equal(a.n_run, 0);
        assert_int_equal(b.n_episode, 3 * 4);
        for (i = 0; i < a.n_episode; i++) {
            const maze_episode_row_t *x = &a.episode[i];
            const maze_episode_row_t *y = &b.episode[i];
            assert_int_equal(x->run, 1 + i / 4);
            assert_int_equal(x->episode, 1 + i % 4);
            assert_true(x->steps >= 14u);  // none beats the shortest path
            assert_true(x->reached_goal);
            assert_true(x->wall_s == 0.0);
            assert_true(y->wall_s == 0.5);
            assert_int_equal(x->steps, y->steps);
            assert_true(x->updates == y->updates);
            assert_int_equal(x->reached_goal, y->reached_goal);
            if (kinds[k] == AGENT_Q_LEARNING) {
                assert_true(x->updates == x->steps);  // one Q update per real step, no planning
            } else {
                assert_true(x->updates >= x->steps);
            }
        }
        // Runs are independent streams: run 1 and run 2 do not repeat each other.
        assert_true(a.episode[0].steps != a.episode[4].steps ||
                    a.episode[1].steps != a.episode[5].steps ||
                    a.episode[2].steps != a.episode[6].steps);
    }
}

static void test_runner_seed_matters_and_step_cap(void **state)
{
    static rows_t a;
    static rows_t b;
    maze_run_config_t cfg;
    int i;
    int differ = 0;
    (void)state;

    assert_int_equal(parse_(dyna_maze_), 0);
    cfg = config_(AGENT_DYNA_QPC, &a);
    assert_int_equal(maze_run(&cfg, NULL), 0);
    cfg = config_(AGENT_DYNA_QPC, &b);
    cfg.seed = 43;
    assert_int_equal(maze_run(&cfg, NULL), 0);
    for (i = 0; i < a.n_episode; i++) {
        differ += a.episode[i].steps != b.episode[i].steps;
    }
    assert_true(differ > 0);
    assert_true(maze_run_seed(1, 1) != maze_run_seed(1, 2));
    assert_true(maze_run_seed(1, 1) != maze_run_seed(2, 1));

    // An episode that hits max_steps just ends.
    cfg = config_(AGENT_Q_LEARNING, &a);
    cfg.max_steps = 5;
    assert_int_equal(maze_run(&cfg, NULL), 0);
    assert_int_equal(a.n_episode, 12);
    for (i = 0; i < a.n_episode; i++) {
        assert_int_equal(a.episode[i].steps, 5);
        assert_false(a.episode[i].reached_goal);
    }
}

static void test_runner_until_optimal(void **state)
{
    static rows_t a;
    static rows_t b;
    maze_run_config_t cfg;
    int i;
    (void)state;

    assert_int_equal(parse_("S.....\n.####.\n.....G\n"), 0);
    cfg = config_(AGENT_DYNA_Q, &a);
    cfg.until_optimal = 1.0;
    cfg.max_episodes = 200;
    cfg.params.epsilon = 0.2f;
    assert_int_equal(maze_run(&cfg, NULL), 0);
    cfg.ctx = &b;
    memset(&b, 0, sizeof b);
    assert_int_equal(maze_run(&cfg, NULL), 0);
    assert_int_equal(a.n_episode, 0);
    assert_int_equal(a.n_run, 3);
    for (i = 0; i < a.n_run; i++) {
        assert_int_equal(a.run[i].run, i + 1);
        assert_true(a.run[i].episodes >= 1u && a.run[i].episodes <= 200u);
        assert_true(a.run[i].real_steps >= 7u * a.run[i].episodes);
        assert_true(a.run[i].updates >= a.run[i].real_steps);
        assert_int_equal(a.run[i].episodes, b.run[i].episodes);
        assert_true(a.run[i].real_steps == b.run[i].real_steps);
        assert_true(a.run[i].updates == b.run[i].updates);
        assert_int_equal(a.run[i].optimal, b.run[i].optimal);
        // Stopping at the cap is reported as not optimal.
        if (a.run[i].optimal == false) {
            assert_int_equal(a.run[i].episodes, 200);
        }
    }

    // A cap of one episode: one episode per run, whatever happens.
    cfg.max_episodes = 1;
    cfg.ctx = &a;
    memset(&a, 0, sizeof a);
    assert_int_equal(maze_run(&cfg, NULL), 0);
    assert_int_equal(a.n_run, 3);
    for (i = 0; i < a.n_run; i++) {
        assert_int_equal(a.run[i].episodes, 1);
    }
}

static void test_greedy_within(void **state)
{
    agent_space_t sp;
    agent_config_t acfg;
    agent_t ag;
    (void)state;

    // S . G: right, right.
    assert_int_equal(parse_("S.G\n"), 0);
    maze_space(&maze_, &sp);
    acfg.kind = AGENT_Q_LEARNING;
    acfg.space = &sp;
    acfg.params = agent_default_params();
    acfg.params.alpha = 1.0f;
    acfg.storage = &agent_storage_maze;
    acfg.seed = 1;
    assert_int_equal(agent_init(&ag, &acfg), 0);
    // Knowing nothing, greedy goes up (action 0) and stays put.
    assert_false(maze_greedy_within(&maze_, &ag, 1.0));
    assert_false(maze_greedy_within(&maze_, &ag, 100.0));
    agent_observe(&ag, maze_state(&maze_, pos_(0, 1)), MAZE_RIGHT, 1.0f,
                  maze_state(&maze_, pos_(0, 2)), true);
    assert_false(maze_greedy_within(&maze_, &ag, 1.0));
    agent_observe(&ag, maze_state(&maze_, pos_(0, 0)), MAZE_RIGHT, 0.0f,
                  maze_state(&maze_, pos_(0, 1)), false);
    assert_int_equal(agent_greedy(&ag, maze_state(&maze_, pos_(0, 0))), MAZE_RIGHT);
    assert_true(maze_greedy_within(&maze_, &ag, 1.0));
    // The budget is floor(F x shortest): 1.4 x 2 = 2 steps still suffice, 0.9 x 2 = 1 does not.
    assert_true(maze_greedy_within(&maze_, &ag, 1.4));
    assert_false(maze_greedy_within(&maze_, &ag, 0.9));
}

static void test_runner_check(void **state)
{
    static rows_t a;
    agent_storage_t small;
    maze_run_config_t cfg;
    const char *why = NULL;
    (void)state;

    assert_int_equal(parse_(dyna_maze_), 0);
    cfg = config_(AGENT_DYNA_QPC, &a);
    assert_int_equal(maze_run_check(&cfg, &why), 0);

    // 6 x 9 needs 3 + 4 bits: 128 dense Q rows.
    small = agent_storage_maze;
    small.q_states = 64;
    cfg.storage = &small;
    assert_int_equal(maze_run_check(&cfg, &why), -1);
    assert_non_null(strstr(why, "too big for the agent profile"));
    assert_int_equal(maze_run(&cfg, &why), -1);
    assert_int_equal(a.n_episode, 0);
    small.q_states = 128;
    assert_int_equal(maze_run_check(&cfg, &why), 0);

    cfg = config_(AGENT_DYNA_QPC, &a);
    cfg.runs = 0;
    assert_int_equal(maze_run_check(&cfg, &why), -1);
    cfg = config_(AGENT_DYNA_QPC, &a);
    cfg.episodes = 0;
    assert_int_equal(maze_run_check(&cfg, &why), -1);
    cfg = config_(AGENT_DYNA_QPC, &a);
    cfg.until_optimal = 0.5;
    assert_int_equal(maze_run_check(&cfg, &why), -1);
    cfg = config_(AGENT_DYNA_QPC, &a);
    cfg.params.epsilon = 1.5f;
    assert_int_equal(maze_run_check(&cfg, &why), -1);
    assert_non_null(strstr(why, "agent_init"));
    cfg = config_(AGENT_DYNA_QPC, &a);
    cfg.max_steps = 0;
    assert_int_equal(maze_run_check(&cfg, &why), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parse_dyna_maze),
        cmocka_unit_test(test_crlf_and_trailing_lines_accepted),
        cmocka_unit_test(test_several_starts_and_goals),
        cmocka_unit_test(test_error_no_start_no_goal),
        cmocka_unit_test(test_error_ragged_rows),
        cmocka_unit_test(test_error_unknown_character),
        cmocka_unit_test(test_error_unreachable_goal),
        cmocka_unit_test(test_error_empty),
        cmocka_unit_test(test_error_limits),
        cmocka_unit_test(test_refine),
        cmocka_unit_test(test_error_garbage),
        cmocka_unit_test(test_moves),
        cmocka_unit_test(test_state_encoding),
        cmocka_unit_test(test_runner_rows_and_determinism),
        cmocka_unit_test(test_runner_seed_matters_and_step_cap),
        cmocka_unit_test(test_runner_until_optimal),
        cmocka_unit_test(test_greedy_within),
        cmocka_unit_test(test_runner_check),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
