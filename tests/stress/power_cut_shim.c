// LD_PRELOAD power-cut injector (docs/durability.md, "The power-cut test"): records, for the files and directories
// under one directory, what a power cut would leave of them, so that after SIGKILL a harness can rebuild that
// directory as the disk would hold it (tests/bench/power_cut.py, cut()). The process itself keeps running on the
// real files: reads see everything written, as they would before a power cut.
//
// The rule (POSIX's, stricter than ext4's default): a file's content is durable as of its last fsync/fdatasync
// (sync_file_range, O_DIRECT and close make nothing durable); a directory's entries (create, rename, unlink, mkdir)
// are durable as of the directory's last fsync. GRASPSIM_POWER_CUT_RULE=journal is kinder, like a journalling file
// system committing its metadata in order: any fsync also makes every directory entry durable (file data still
// needs its own fsync). GRASPSIM_POWER_CUT_RULE=nosync is a disk that ignores flushes (a lying write cache): fsync
// makes nothing durable, so a cut loses everything written since the start; it shows the test is not vacuous.
//
// Environment: GRASPSIM_POWER_CUT_DIR (the directory watched; must exist), GRASPSIM_POWER_CUT_STATE (an existing
// directory, outside it, for the record). Without both the library does nothing but forward the calls.
//
// The record, keyed by inode: STATE/inodes/KEY holds a file's durable content, STATE/dirs/KEY a directory's
// durable entries ("f KEY NAME" or "d KEY NAME" per line). KEY is DEV-INO-0 for an inode that existed when the
// process started (its durable content is what it held then: copied before the first call that could change or
// unlink it, or, if none came, the live file itself at the cut) and DEV-INO-pPID-N for one created since (empty
// until its first fsync); inode numbers are reused, keys are not. The record is written with plain writes: it
// must outlive a SIGKILL, not a real power cut.
//
// Seen: libc's open/openat/creat (and their 64-bit and _FORTIFY_SOURCE forms), fopen, dup*, close, write, writev,
// pwrite*, fallocate, mmap, fsync, fdatasync, syncfs, sync, rename*, unlink*, truncate, mkdir*. Not seen (so
// not modelled): raw syscalls, io_uring, copy_file_range/sendfile/splice into a file, hard links, symlinks,
// O_TMPFILE + linkat. One lock serializes the record; the calls themselves run in the caller's thread.
#define _GNU_SOURCE
#include <dirent.h>
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/uio.h>
#include <unistd.h>

#define FD_MAX 65536
#define RANGES_MAX 1024

// glibc's _FORTIFY_SOURCE entry points of open(), declared by its headers only when fortifying.
int __open_2(const char* path, int flags);
int __open64_2(const char* path, int flags);
int __openat_2(int dirfd, const char* path, int flags);
int __openat64_2(int dirfd, const char* path, int flags);

// The next definition of a function we replace (libc's).
#define REAL(f) (*({ if (!real_##f) real_##f = dlsym(RTLD_NEXT, #f); real_##f; }))
#define DECLARE_REAL(f) static __typeof__(f)* real_##f
DECLARE_REAL(open); DECLARE_REAL(open64); DECLARE_REAL(openat); DECLARE_REAL(openat64); DECLARE_REAL(creat);
DECLARE_REAL(creat64); DECLARE_REAL(__open_2); DECLARE_REAL(__open64_2); DECLARE_REAL(__openat_2);
DECLARE_REAL(__openat64_2); DECLARE_REAL(fopen); DECLARE_REAL(fopen64); DECLARE_REAL(fclose); DECLARE_REAL(close);
DECLARE_REAL(dup); DECLARE_REAL(dup2); DECLARE_REAL(dup3); DECLARE_REAL(write); DECLARE_REAL(writev);
DECLARE_REAL(pwrite); DECLARE_REAL(pwrite64); DECLARE_REAL(pwritev); DECLARE_REAL(pwritev64);
DECLARE_REAL(pwritev2); DECLARE_REAL(pwritev64v2); DECLARE_REAL(fallocate); DECLARE_REAL(fallocate64);
DECLARE_REAL(mmap); DECLARE_REAL(mmap64); DECLARE_REAL(fsync); DECLARE_REAL(fdatasync); DECLARE_REAL(syncfs);
DECLARE_REAL(sync); DECLARE_REAL(rename); DECLARE_REAL(renameat); DECLARE_REAL(renameat2); DECLARE_REAL(unlink);
DECLARE_REAL(unlinkat); DECLARE_REAL(mkdir); DECLARE_REAL(mkdirat); DECLARE_REAL(truncate);
DECLARE_REAL(truncate64);

struct range { off_t a, b; };
struct inode {           // an inode under the directory that this process opened for writing or created
  dev_t dev;
  ino_t ino;
  char key[96];
  int whole;             // copy the whole file at the next fsync (ranges overflowed or a write went unseen)
  int blind;             // written where we cannot see (shared writable mmap, stdio): always copy it whole
  int fresh;             // created by this process: nothing of it was durable at start
  size_t n;
  struct range r[RANGES_MAX];  // written since the last fsync (a superset is fine: fsync makes it all durable)
  struct inode* next;
};

static char g_dir[PATH_MAX], g_state[PATH_MAX];
static size_t g_dir_len;
static int g_on, g_journal, g_nosync;
static unsigned long g_created;
static struct inode* g_inodes;
static struct inode* g_fd[FD_MAX];   // fds opened for writing on a watched file; read without the lock at first
static char g_fd_sync[FD_MAX];       // O_SYNC / O_DSYNC: each write is durable when it returns
static char g_buf[1 << 20];
// Every change to the record, and each write() + lseek() on a watched fd, under one lock: simple, and the
// server's writers (SQLite) serialize their writes anyway.
static pthread_mutex_t g_lock = PTHREAD_MUTEX_INITIALIZER;

static int watched_fd(int fd) { return g_on && fd >= 0 && fd < FD_MAX && __atomic_load_n(&g_fd[fd], __ATOMIC_ACQUIRE); }

// An absolute, lexically normalised path (no symlinks resolved: the harness gives the directory's real path).
static int absolute(int dirfd, const char* path, char* out) {
  char joined[2 * PATH_MAX];
  if (path[0] == '/') {
    snprintf(joined, sizeof joined, "%s", path);
  } else {
    char base[PATH_MAX], link[64];
    ssize_t n;
    if (dirfd == AT_FDCWD) {
      if (!getcwd(base, sizeof base)) return -1;
    } else {
      snprintf(link, sizeof link, "/proc/self/fd/%d", dirfd);
      if ((n = readlink(link, base, sizeof base - 1)) < 0) return -1;
      base[n] = 0;
    }
    snprintf(joined, sizeof joined, "%s/%s", base, path);
  }
  size_t len = 0;
  for (char *save, *part = strtok_r(joined, "/", &save); part; part = strtok_r(NULL, "/", &save)) {
    if (!strcmp(part, ".")) continue;
    if (!strcmp(part, "..")) {  // drop the last component
      while (len > 0 && out[len - 1] != '/') len--;
      if (len > 0) len--;
      continue;
    }
    size_t n = strlen(part);
    if (len + 1 + n >= PATH_MAX) return -1;
    out[len++] = '/';
    memcpy(out + len, part, n);
    len += n;
  }
  if (len == 0) out[len++] = '/';
  out[len] = 0;
  return 0;
}

static int inside(const char* abs) {
  return !strncmp(abs, g_dir, g_dir_len) && (abs[g_dir_len] == 0 || abs[g_dir_len] == '/');
}

static int watched_path(int dirfd, const char* path, char* abs) {
  return g_on && path && absolute(dirfd, path, abs) == 0 && inside(abs);
}

static struct inode* find_inode(const struct stat* st) {
  for (struct inode* i = g_inodes; i; i = i->next)
    if (i->dev == st->st_dev && i->ino == st->st_ino) return i;
  return NULL;
}

// The record of an inode; one that existed before this process started if we have not seen it created.
static struct inode* get_inode(const struct stat* st) {
  struct inode* i = find_inode(st);
  if (i) return i;
  i = calloc(1, sizeof *i);
  i->dev = st->st_dev;
  i->ino = st->st_ino;
  snprintf(i->key, sizeof i->key, "%lu-%lu-0", (unsigned long)st->st_dev, (unsigned long)st->st_ino);
  i->next = g_inodes;
  g_inodes = i;
  return i;
}

// An inode this process just created: a new key (its number may be a deleted file's), nothing durable yet.
static struct inode* new_inode(const struct stat* st) {
  struct inode* i = get_inode(st);
  snprintf(i->key, sizeof i->key, "%lu-%lu-p%d-%lu", (unsigned long)st->st_dev, (unsigned long)st->st_ino,
           (int)getpid(), ++g_created);
  i->whole = i->blind = 0;
  i->fresh = 1;
  i->n = 0;
  return i;
}

static void record_path(char* out, const char* kind, const char* key, const char* suffix) {
  snprintf(out, PATH_MAX, "%s/%s/%s%s", g_state, kind, key, suffix);
}

static int has_copy(const struct inode* i) {
  char p[PATH_MAX];
  record_path(p, "inodes", i->key, "");
  return access(p, F_OK) == 0;
}

// Copies [a, b) of src into dst at the same offsets.
static int copy_range(int src, int dst, off_t a, off_t b) {
  while (a < b) {
    size_t want = (size_t)(b - a) < sizeof g_buf ? (size_t)(b - a) : sizeof g_buf;
    ssize_t n = pread(src, g_buf, want, a);
    if (n <= 0) return n == 0 ? 0 : -1;
    if (REAL(pwrite)(dst, g_buf, n, a) != n) return -1;
    a += n;
  }
  return 0;
}

// Makes the current content of the file at `source` (a path or /proc/self/fd/N) the durable content of inode i:
// the whole file, or only the ranges written since the last time when they are known to be all.
static void make_content_durable(struct inode* i, const char* source, off_t size, int whole) {
  char p[PATH_MAX];
  record_path(p, "inodes", i->key, "");
  whole = whole || i->whole || i->blind || access(p, F_OK) != 0;
  int src = REAL(open)(source, O_RDONLY | O_CLOEXEC), dst = REAL(open)(p, O_WRONLY | O_CREAT | O_CLOEXEC, 0600);
  if (src >= 0 && dst >= 0) {
    int failed = 0;
    if (whole) {
      failed = copy_range(src, dst, 0, size);
    } else {
      for (size_t k = 0; k < i->n; k++)
        failed |= copy_range(src, dst, i->r[k].a, i->r[k].b < size ? i->r[k].b : size);
    }
    if (!failed && ftruncate(dst, size) == 0) i->n = i->whole = 0;
  }
  if (src >= 0) REAL(close)(src);
  if (dst >= 0) REAL(close)(dst);
}

// Keeps the content an inode that existed at start still has, before a call that may change or unlink it.
static void keep_baseline(const char* abs) {
  struct stat st;
  if (lstat(abs, &st) != 0 || !S_ISREG(st.st_mode)) return;
  struct inode* i = get_inode(&st);
  if (i->fresh || has_copy(i)) return;
  // Copied aside and renamed: a copy cut short by SIGKILL must not stand for the untouched file.
  char tmp[PATH_MAX], p[PATH_MAX];
  record_path(tmp, "inodes", i->key, ".baseline");
  record_path(p, "inodes", i->key, "");
  int src = REAL(open)(abs, O_RDONLY | O_CLOEXEC), dst = REAL(open)(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (src >= 0 && dst >= 0 && copy_range(src, dst, 0, st.st_size) == 0) REAL(rename)(tmp, p);
  if (src >= 0) REAL(close)(src);
  if (dst >= 0) REAL(close)(dst);
}

// Makes a directory's entries as they are now its durable entries (source: a path or /proc/self/fd/N).
static void make_entries_durable(const char* source, const struct stat* st) {
  char tmp[PATH_MAX], p[PATH_MAX];
  record_path(tmp, "dirs", get_inode(st)->key, ".tmp");
  record_path(p, "dirs", get_inode(st)->key, "");
  DIR* d = opendir(source);
  FILE* out = d ? REAL(fopen)(tmp, "we") : NULL;
  if (out) {
    for (struct dirent* e; (e = readdir(d));) {
      struct stat es;
      if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
      if (fstatat(dirfd(d), e->d_name, &es, AT_SYMLINK_NOFOLLOW) != 0) continue;
      if (!S_ISREG(es.st_mode) && !S_ISDIR(es.st_mode)) continue;  // symlinks, sockets: not modelled
      struct inode* i = find_inode(&es);
      if (i) fprintf(out, "%c %s %s\n", S_ISDIR(es.st_mode) ? 'd' : 'f', i->key, e->d_name);
      else fprintf(out, "%c %lu-%lu-0 %s\n", S_ISDIR(es.st_mode) ? 'd' : 'f', (unsigned long)es.st_dev,
                   (unsigned long)es.st_ino, e->d_name);
    }
    if (REAL(fclose)(out) == 0) REAL(rename)(tmp, p);
  }
  if (d) closedir(d);
}

// Every directory under `path` (and, for sync(), every file's content) made durable as it is now.
static void make_tree_durable(const char* path, int files) {
  struct stat st;
  if (lstat(path, &st) != 0) return;
  if (S_ISREG(st.st_mode) && files) make_content_durable(get_inode(&st), path, st.st_size, 1);
  if (!S_ISDIR(st.st_mode)) return;
  make_entries_durable(path, &st);
  DIR* d = opendir(path);
  for (struct dirent* e; d && (e = readdir(d));) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
    char child[PATH_MAX];
    if (snprintf(child, sizeof child, "%s/%s", path, e->d_name) < (int)sizeof child) make_tree_durable(child, files);
  }
  if (d) closedir(d);
}

__attribute__((constructor)) static void init(void) {
  const char *dir = getenv("GRASPSIM_POWER_CUT_DIR"), *state = getenv("GRASPSIM_POWER_CUT_STATE");
  const char* rule = getenv("GRASPSIM_POWER_CUT_RULE");
  if (!dir || !state || !realpath(dir, g_dir) || !realpath(state, g_state)) return;
  g_dir_len = strlen(g_dir);
  g_journal = rule && !strcmp(rule, "journal");
  g_nosync = rule && !strcmp(rule, "nosync");
  char p[PATH_MAX];
  snprintf(p, sizeof p, "%s/inodes", g_state);
  REAL(mkdir)(p, 0700);
  snprintf(p, sizeof p, "%s/dirs", g_state);
  REAL(mkdir)(p, 0700);
  // The first process on this record: what is on disk now is durable (it is what the last power cut left).
  struct stat st;
  char root[PATH_MAX];
  stat(g_dir, &st);
  snprintf(root, sizeof root, "%lu-%lu-0", (unsigned long)st.st_dev, (unsigned long)st.st_ino);
  record_path(p, "dirs", root, "");
  if (access(p, F_OK) != 0) make_tree_durable(g_dir, 0);
  g_on = 1;
}

// --- opening, closing ---------------------------------------------------------------------------------------

struct opening { int on, existed; char abs[PATH_MAX]; };

static int writes(int flags) { return (flags & O_ACCMODE) != O_RDONLY || (flags & O_TRUNC); }

// Before an open under the directory: the lock, and the file's content at start kept if the open may change it.
static void before_open(int dirfd, const char* path, int flags, struct opening* o) {
  o->on = watched_path(dirfd, path, o->abs);
  if (!o->on) return;
  pthread_mutex_lock(&g_lock);
  struct stat st;
  o->existed = stat(o->abs, &st) == 0;
  if (o->existed && writes(flags)) keep_baseline(o->abs);
}

static void watch_fd(int fd, struct inode* i, int sync) {
  if (fd < 0 || fd >= FD_MAX) return;
  g_fd_sync[fd] = (char)sync;
  __atomic_store_n(&g_fd[fd], i, __ATOMIC_RELEASE);
}

static void after_open(struct opening* o, int fd, int flags, int blind) {
  if (!o->on) return;
  int saved = errno;
  struct stat st;
  if (fd >= 0 && fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) {
    int created = !o->existed || (flags & O_TMPFILE) == O_TMPFILE;
    struct inode* i = created ? new_inode(&st) : get_inode(&st);
    i->blind |= blind;
    watch_fd(fd, writes(flags) ? i : NULL, (flags & O_DSYNC) != 0);  // O_SYNC includes O_DSYNC's bit
  } else if (fd >= 0) {
    watch_fd(fd, NULL, 0);  // a directory: its fsync is found by path
  }
  pthread_mutex_unlock(&g_lock);
  errno = saved;
}

#define MODE_ARG(flags)                                              \
  mode_t mode = 0;                                                   \
  if ((flags) & (O_CREAT | __O_TMPFILE)) {                           \
    va_list ap;                                                      \
    va_start(ap, flags);                                             \
    mode = va_arg(ap, mode_t);                                       \
    va_end(ap);                                                      \
  }

#define OPEN_AT(dirfd, path, flags, call)      \
  struct opening o;                            \
  before_open(dirfd, path, flags, &o);         \
  int fd = call;                               \
  after_open(&o, fd, flags, 0);                \
  return fd;

int open(const char* path, int flags, ...) { MODE_ARG(flags) OPEN_AT(AT_FDCWD, path, flags, REAL(open)(path, flags, mode)) }
int open64(const char* path, int flags, ...) { MODE_ARG(flags) OPEN_AT(AT_FDCWD, path, flags, REAL(open64)(path, flags, mode)) }
int openat(int d, const char* path, int flags, ...) { MODE_ARG(flags) OPEN_AT(d, path, flags, REAL(openat)(d, path, flags, mode)) }
int openat64(int d, const char* path, int flags, ...) { MODE_ARG(flags) OPEN_AT(d, path, flags, REAL(openat64)(d, path, flags, mode)) }
int __open_2(const char* path, int flags) { OPEN_AT(AT_FDCWD, path, flags, REAL(__open_2)(path, flags)) }
int __open64_2(const char* path, int flags) { OPEN_AT(AT_FDCWD, path, flags, REAL(__open64_2)(path, flags)) }
int __openat_2(int d, const char* path, int flags) { OPEN_AT(d, path, flags, REAL(__openat_2)(d, path, flags)) }
int __openat64_2(int d, const char* path, int flags) { OPEN_AT(d, path, flags, REAL(__openat64_2)(d, path, flags)) }
int creat(const char* path, mode_t mode) { OPEN_AT(AT_FDCWD, path, O_CREAT | O_WRONLY | O_TRUNC, REAL(creat)(path, mode)) }
int creat64(const char* path, mode_t mode) { OPEN_AT(AT_FDCWD, path, O_CREAT | O_WRONLY | O_TRUNC, REAL(creat64)(path, mode)) }

// stdio writes through libc's internal write(), which we do not see: such files are copied whole at each fsync.
static int stdio_flags(const char* mode) {
  int plus = strchr(mode, '+') != NULL;
  if (mode[0] == 'w') return O_CREAT | O_TRUNC | (plus ? O_RDWR : O_WRONLY);
  if (mode[0] == 'a') return O_CREAT | O_APPEND | (plus ? O_RDWR : O_WRONLY);
  return plus ? O_RDWR : O_RDONLY;
}

#define FOPEN(call)                                           \
  struct opening o;                                           \
  int flags = stdio_flags(mode);                              \
  before_open(AT_FDCWD, path, flags, &o);                     \
  FILE* f = call;                                             \
  after_open(&o, f ? fileno(f) : -1, flags, 1);               \
  return f;

FILE* fopen(const char* path, const char* mode) { FOPEN(REAL(fopen)(path, mode)) }
FILE* fopen64(const char* path, const char* mode) { FOPEN(REAL(fopen64)(path, mode)) }

static void forget_fd(int fd) {
  if (watched_fd(fd)) watch_fd(fd, NULL, 0);
}

int close(int fd) {
  forget_fd(fd);
  return REAL(close)(fd);
}

int fclose(FILE* f) {
  forget_fd(fileno(f));
  return REAL(fclose)(f);
}

static int copy_fd(int from, int to) {
  if (to >= 0 && to < FD_MAX && to != from) {
    struct inode* i = watched_fd(from) ? g_fd[from] : NULL;
    watch_fd(to, i, i ? g_fd_sync[from] : 0);
  }
  return to;
}

int dup(int fd) { return copy_fd(fd, REAL(dup)(fd)); }
int dup2(int fd, int to) { return copy_fd(fd, REAL(dup2)(fd, to)); }
int dup3(int fd, int to, int flags) { return copy_fd(fd, REAL(dup3)(fd, to, flags)); }

// --- writing ------------------------------------------------------------------------------------------------

static void mark(struct inode* i, off_t a, off_t b) {
  if (!i || a >= b) return;
  if (i->n > 0 && a <= i->r[i->n - 1].b && b >= i->r[i->n - 1].a) {  // appends and rewrites merge
    if (a < i->r[i->n - 1].a) i->r[i->n - 1].a = a;
    if (b > i->r[i->n - 1].b) i->r[i->n - 1].b = b;
  } else if (i->n < RANGES_MAX) {
    i->r[i->n++] = (struct range){a, b};
  } else {
    i->whole = 1;
  }
}

static void sync_fd(int fd);

// After a write of n bytes at offset a (a < 0: at the file position, now after them).
static void wrote(int fd, off_t a, ssize_t n) {
  if (n <= 0) return;
  int saved = errno;
  if (a < 0) {
    off_t end = lseek(fd, 0, SEEK_CUR);
    if (end < 0) g_fd[fd]->whole = 1;
    a = end - n;
  }
  mark(g_fd[fd], a, a + n);
  errno = saved;
}

// write() and writev() at the file position: the write and the lseek() that finds where it went under the lock,
// so another thread's write on the same fd cannot come between them.
#define WRITE_AT_POSITION(call)              \
  if (!watched_fd(fd)) return call;          \
  pthread_mutex_lock(&g_lock);               \
  ssize_t n = call;                          \
  if (g_fd[fd]) wrote(fd, -1, n);            \
  pthread_mutex_unlock(&g_lock);             \
  if (n > 0 && g_fd_sync[fd]) sync_fd(fd);   \
  return n;

#define WRITE_AT(offset, call)                 \
  ssize_t n = call;                            \
  if (n > 0 && watched_fd(fd)) {               \
    int saved = errno;                         \
    pthread_mutex_lock(&g_lock);               \
    if (g_fd[fd]) mark(g_fd[fd], offset, (offset) + n); \
    pthread_mutex_unlock(&g_lock);             \
    if (g_fd_sync[fd]) sync_fd(fd);            \
    errno = saved;                             \
  }                                            \
  return n;

ssize_t write(int fd, const void* buf, size_t count) { WRITE_AT_POSITION(REAL(write)(fd, buf, count)) }
ssize_t writev(int fd, const struct iovec* iov, int cnt) { WRITE_AT_POSITION(REAL(writev)(fd, iov, cnt)) }
ssize_t pwrite(int fd, const void* buf, size_t count, off_t off) { WRITE_AT(off, REAL(pwrite)(fd, buf, count, off)) }
ssize_t pwrite64(int fd, const void* buf, size_t count, off64_t off) { WRITE_AT(off, REAL(pwrite64)(fd, buf, count, off)) }
ssize_t pwritev(int fd, const struct iovec* iov, int cnt, off_t off) { WRITE_AT(off, REAL(pwritev)(fd, iov, cnt, off)) }
ssize_t pwritev64(int fd, const struct iovec* iov, int cnt, off64_t off) { WRITE_AT(off, REAL(pwritev64)(fd, iov, cnt, off)) }

// pwritev2 may write at the position or append (RWF_APPEND): rare, so the file is simply copied whole.
#define WRITE_SOMEWHERE(call)                                    \
  ssize_t n = call;                                              \
  if (n > 0 && watched_fd(fd)) {                                 \
    pthread_mutex_lock(&g_lock);                                 \
    if (g_fd[fd]) g_fd[fd]->whole = 1;                           \
    pthread_mutex_unlock(&g_lock);                               \
    if (g_fd_sync[fd]) sync_fd(fd);                              \
  }                                                              \
  return n;

ssize_t pwritev2(int fd, const struct iovec* iov, int cnt, off_t off, int flags) {
  WRITE_SOMEWHERE(REAL(pwritev2)(fd, iov, cnt, off, flags))
}
ssize_t pwritev64v2(int fd, const struct iovec* iov, int cnt, off64_t off, int flags) {
  WRITE_SOMEWHERE(REAL(pwritev64v2)(fd, iov, cnt, off, flags))
}

// fallocate can punch holes (new zeros) as well as extend (the size is taken at fsync anyway).
static int allocated(int fd, off_t off, off_t len, int r) {
  if (r == 0 && watched_fd(fd)) {
    pthread_mutex_lock(&g_lock);
    if (g_fd[fd]) mark(g_fd[fd], off, off + len);
    pthread_mutex_unlock(&g_lock);
  }
  return r;
}
int fallocate(int fd, int mode, off_t off, off_t len) { return allocated(fd, off, len, REAL(fallocate)(fd, mode, off, len)); }
int fallocate64(int fd, int mode, off64_t off, off64_t len) { return allocated(fd, off, len, REAL(fallocate64)(fd, mode, off, len)); }

// A shared writable mapping changes the file without a call we see (SQLite maps its -shm file, which it never
// syncs and rebuilds after a crash): such a file is copied whole at each fsync.
#define MMAP(call)                                                                    \
  void* p = call;                                                                     \
  if (p != MAP_FAILED && (flags & MAP_SHARED) && (prot & PROT_WRITE) && watched_fd(fd)) { \
    pthread_mutex_lock(&g_lock);                                                      \
    if (g_fd[fd]) g_fd[fd]->blind = 1;                                                \
    pthread_mutex_unlock(&g_lock);                                                    \
  }                                                                                   \
  return p;

void* mmap(void* addr, size_t len, int prot, int flags, int fd, off_t off) { MMAP(REAL(mmap)(addr, len, prot, flags, fd, off)) }
void* mmap64(void* addr, size_t len, int prot, int flags, int fd, off64_t off) { MMAP(REAL(mmap64)(addr, len, prot, flags, fd, off)) }

// --- making things durable ----------------------------------------------------------------------------------

// After a successful fsync(fd): the file's content, or the directory's entries, become durable.
static void sync_fd(int fd) {
  if (!g_on || g_nosync || fd < 0) return;
  int saved = errno;
  char link[64], target[PATH_MAX];
  snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
  ssize_t len = readlink(link, target, sizeof target - 1);
  struct stat st;
  if (len > 0 && (target[len] = 0, inside(target)) && fstat(fd, &st) == 0) {
    pthread_mutex_lock(&g_lock);
    if (S_ISDIR(st.st_mode)) {
      make_entries_durable(link, &st);
    } else if (S_ISREG(st.st_mode)) {
      struct inode* i = get_inode(&st);
      // Writes through an fd we never saw opened went unseen: then copy the whole file.
      int seen = (fd < FD_MAX && g_fd[fd] == i) || (fcntl(fd, F_GETFL) & O_ACCMODE) == O_RDONLY;
      make_content_durable(i, link, st.st_size, !seen);
    }
    if (g_journal) make_tree_durable(g_dir, 0);
    pthread_mutex_unlock(&g_lock);
  }
  errno = saved;
}

int fsync(int fd) {
  int r = REAL(fsync)(fd);
  if (r == 0) sync_fd(fd);
  return r;
}

int fdatasync(int fd) {
  int r = REAL(fdatasync)(fd);
  if (r == 0) sync_fd(fd);
  return r;
}

static void sync_everything(void) {
  if (!g_on || g_nosync) return;
  int saved = errno;
  pthread_mutex_lock(&g_lock);
  make_tree_durable(g_dir, 1);
  pthread_mutex_unlock(&g_lock);
  errno = saved;
}

int syncfs(int fd) {
  int r = REAL(syncfs)(fd);
  if (r == 0) sync_everything();  // whichever file system fd is on: good enough for a test directory
  return r;
}

void sync(void) {
  REAL(sync)();
  sync_everything();
}

// --- directory entries: only the content an inode had at start needs keeping before these --------------------

#define BEFORE_ENTRY_CHANGE(dirfd, path)                  \
  char abs[PATH_MAX];                                     \
  int on = watched_path(dirfd, path, abs);                \
  if (on) {                                               \
    pthread_mutex_lock(&g_lock);                          \
    keep_baseline(abs);                                   \
  }
#define UNLOCK_AND_RETURN(r) \
  if (on) pthread_mutex_unlock(&g_lock); \
  return r;

int unlink(const char* path) {
  BEFORE_ENTRY_CHANGE(AT_FDCWD, path)
  int r = REAL(unlink)(path);
  UNLOCK_AND_RETURN(r)
}

int unlinkat(int d, const char* path, int flags) {
  BEFORE_ENTRY_CHANGE(d, path)
  int r = REAL(unlinkat)(d, path, flags);
  UNLOCK_AND_RETURN(r)
}

int truncate(const char* path, off_t len) {
  BEFORE_ENTRY_CHANGE(AT_FDCWD, path)
  int r = REAL(truncate)(path, len);
  UNLOCK_AND_RETURN(r)
}

int truncate64(const char* path, off64_t len) {
  BEFORE_ENTRY_CHANGE(AT_FDCWD, path)
  int r = REAL(truncate64)(path, len);
  UNLOCK_AND_RETURN(r)
}

// rename: both the file moved and the one it replaces (unlinked by it).
static int renaming(int from_dir, const char* from, int to_dir, const char* to, char* abs) {
  char other[PATH_MAX];
  int moved = watched_path(from_dir, from, abs), replaced = watched_path(to_dir, to, other);
  if (!moved && !replaced) return 0;
  pthread_mutex_lock(&g_lock);
  if (moved) keep_baseline(abs);
  if (replaced) keep_baseline(other);
  return 1;
}

int rename(const char* from, const char* to) {
  char abs[PATH_MAX];
  int on = renaming(AT_FDCWD, from, AT_FDCWD, to, abs);
  int r = REAL(rename)(from, to);
  UNLOCK_AND_RETURN(r)
}

int renameat(int fd, const char* from, int td, const char* to) {
  char abs[PATH_MAX];
  int on = renaming(fd, from, td, to, abs);
  int r = REAL(renameat)(fd, from, td, to);
  UNLOCK_AND_RETURN(r)
}

int renameat2(int fd, const char* from, int td, const char* to, unsigned int flags) {
  char abs[PATH_MAX];
  int on = renaming(fd, from, td, to, abs);
  int r = REAL(renameat2)(fd, from, td, to, flags);
  UNLOCK_AND_RETURN(r)
}

// A new directory: a new key, no durable entries until it is fsync'ed itself.
static int made_dir(int dirfd, const char* path, int r) {
  char abs[PATH_MAX];
  struct stat st;
  if (r == 0 && watched_path(dirfd, path, abs)) {
    int saved = errno;
    pthread_mutex_lock(&g_lock);
    if (stat(abs, &st) == 0) new_inode(&st);
    pthread_mutex_unlock(&g_lock);
    errno = saved;
  }
  return r;
}

int mkdir(const char* path, mode_t mode) { return made_dir(AT_FDCWD, path, REAL(mkdir)(path, mode)); }
int mkdirat(int d, const char* path, mode_t mode) { return made_dir(d, path, REAL(mkdirat)(d, path, mode)); }
