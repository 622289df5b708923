#!/usr/bin/env bash
# Integration test of deploy/slurm/render.sbatch on a real one-node Slurm cluster.
#
#   bash tests/slurm/run_slurm_test.sh path/to/toonray
#
# Starts its own munged, slurmctld and slurmd (as root, configured for this host only, with
# every file in a fresh temporary directory and on free high ports; nothing in /etc is read or
# changed), then:
#   1. submits `sbatch --array=1-3 render.sbatch keys 1 9 in out --size 160x90` and checks that
#      every task completed, each log names its shard, and out/ holds exactly the 9 frames (no
#      extra or temporary files), each byte-identical to a local `toonray batch --jobs 1` render;
#   2. submits frames 1-10 as a 2-task array while frame 10's OBJ is missing: the task with
#      frame 10 must end FAILED with exit code 1, the other COMPLETED, and the finished frames
#      must not be rendered again (--resume);
#   3. adds frame 10 and submits the same array again (this time finding toonray on PATH):
#      both tasks complete, frame 10 matches the local render, frames 1-9 are untouched.
# The daemons are stopped on every exit (trap), by the PIDs the test started.
#
# Exit status: 0 passed; 1 failed; 77 skipped because this machine cannot run the daemons (not
# root, the slurm-wlm or munge packages missing, a daemon that does not start; the reason and
# the daemon's log are printed). TOONRAY_REQUIRE_SLURM=1 turns a skip into a failure.
# TOONRAY_SLURM_TEST_TIMEOUT (seconds, default 300) bounds the whole run;
# TOONRAY_SLURM_KEEP=1 keeps the temporary directory for inspection.
set -euo pipefail

readonly SKIP_CODE=77
readonly NAME=slurm_job_array
say() { echo "[$NAME] $*" >&2; }

if [ $# -ne 1 ]; then
    echo "usage: $0 path/to/toonray" >&2
    exit 2
fi
if ! toonray=$(realpath -e "$1" 2>/dev/null) || [ ! -x "$toonray" ]; then
    say "FAIL: toonray binary '$1' not found (build the toonray_cli target first)"
    exit 1
fi
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
sbatch_script=$repo/deploy/slurm/render.sbatch
[ -f "$sbatch_script" ] || { say "FAIL: $sbatch_script is missing"; exit 1; }

timeout_total=${TOONRAY_SLURM_TEST_TIMEOUT:-300}
deadline=$((SECONDS + timeout_total))
remaining() { echo $((deadline - SECONDS)); }

# Nothing from a surrounding Slurm job or user configuration may leak in: the array variables
# would shard the local reference render, SBATCH_* would change the submissions.
while IFS='=' read -r var _; do
    case $var in SLURM_* | SBATCH_* | SALLOC_* | SRUN_* | SQUEUE_* | SINFO_* | SCONTROL_*) unset "$var" ;; esac
done < <(env)
unset TOONRAY

work=""
pids=()        # daemons we started, stopped in reverse order
submitted=()   # job ids to cancel if we stop early

dump_logs() {
    [ -n "$work" ] || return 0
    local f
    for f in "$work"/log/*.log "$work"/job/*.log; do
        [ -s "$f" ] || continue
        # Daemons in the foreground copy their log file to stdout: show each once.
        [[ $f == *.stdout.log && -s ${f%.stdout.log}.log ]] && continue
        echo "----- tail of $f -----"
        tail -n 40 "$f"
    done >&2
}

skip() {
    say "SKIP: $*"
    dump_logs
    if [ "${TOONRAY_REQUIRE_SLURM:-0}" = 1 ]; then
        say "FAIL: TOONRAY_REQUIRE_SLURM=1, so a machine that cannot run Slurm is a failure"
        exit 1
    fi
    exit "$SKIP_CODE"
}

fail() {
    say "FAIL: $*"
    if [ -n "$work" ] && command -v scontrol >/dev/null && [ -n "${SLURM_CONF:-}" ]; then
        local j
        for j in "${submitted[@]}"; do
            echo "----- scontrol show job $j -----"
            scontrol -o show job "$j" 2>&1 | sed -E 's/.*(JobId=[0-9]+ ).*(ArrayTaskId=[^ ]+).*(JobState=[^ ]+ Reason=[^ ]+).*(ExitCode=[^ ]+).*/\1\2 \3 \4/' || true
        done >&2
    fi
    dump_logs
    exit 1
}

stop_pid() { # pid label
    local pid=$1 label=$2 i
    kill -0 "$pid" 2>/dev/null || return 0
    kill -TERM "$pid" 2>/dev/null || true
    for ((i = 0; i < 100; i++)); do
        kill -0 "$pid" 2>/dev/null || break
        sleep 0.1
    done
    if kill -0 "$pid" 2>/dev/null; then
        say "$label (pid $pid) ignored SIGTERM for 10 s; killing it"
        kill -KILL "$pid" 2>/dev/null || true
    fi
    wait "$pid" 2>/dev/null || true
}

cleanup() {
    local rc=$?
    trap - EXIT INT TERM
    set +e
    # Jobs still running (a failure or a timeout) would outlive slurmd: cancel them first.
    if ((${#submitted[@]})) && [ -n "${SLURM_CONF:-}" ]; then
        scancel "${submitted[@]}" 2>/dev/null
        local i
        for ((i = 0; i < 100; i++)); do
            [ -z "$(squeue -h -o %i 2>/dev/null)" ] && break
            sleep 0.1
        done
    fi
    local n
    for ((n = ${#pids[@]} - 1; n >= 0; n--)); do
        stop_pid "${pids[n]%%:*}" "${pids[n]#*:}"
    done
    # The pid files too, in case a daemon forked away from the PID we hold; only processes whose
    # command line names our directory, so a stale file never hits another process.
    if [ -n "$work" ]; then
        local f pid
        for f in "$work"/run/*.pid; do
            [ -f "$f" ] || continue
            pid=$(cat "$f" 2>/dev/null)
            [[ $pid =~ ^[0-9]+$ ]] || continue
            tr '\0' ' ' <"/proc/$pid/cmdline" 2>/dev/null | grep -qF "$work" || continue
            stop_pid "$pid" "$(basename "$f" .pid)"
        done
        if [ "${TOONRAY_SLURM_KEEP:-0}" = 1 ]; then
            say "kept $work"
        else
            rm -rf "$work"
        fi
    fi
    exit "$rc"
}
trap cleanup EXIT
trap 'say "interrupted"; exit 130' INT TERM

# --- can this machine run Slurm? --------------------------------------------------------------
[ "$(id -u)" -eq 0 ] || skip "not root: slurmd must run as root to start jobs (run the test as root)"
missing=()
for c in munged munge unmunge slurmctld slurmd sbatch scontrol squeue sinfo scancel; do
    command -v "$c" >/dev/null 2>&1 || missing+=("$c")
done
((${#missing[@]} == 0)) || skip "missing ${missing[*]}: install the Debian packages slurm-wlm and munge (scripts/install-deps.sh)"

# Unix socket paths (munge's) must stay under 108 bytes: a long TMPDIR falls back to /tmp.
tmp_base=${TMPDIR:-/tmp}
((${#tmp_base} <= 60)) || tmp_base=/tmp
work=$(mktemp -d "$tmp_base/toonray-slurm.XXXXXX")
chmod 0700 "$work"
mkdir -p "$work"/{munge,state,spool,run,log,job}
chmod 0700 "$work/munge"
say "working in $work"

host=$(hostname -s 2>/dev/null || uname -n)
host=${host%%.*}
cpus=$(nproc)
# The array script asks for 2 CPUs a task; a 1-CPU machine still runs it (config_overrides below
# makes slurmd accept the configured count).
((cpus >= 2)) || cpus=2

port_free() { ! timeout 2 bash -c "exec 3<>/dev/tcp/127.0.0.1/$1" 2>/dev/null; }
ctld_port=""
for ((try = 0; try < 50; try++)); do
    p=$((20000 + (RANDOM * 32768 + RANDOM) % 30000))
    if port_free "$p" && port_free "$((p + 1))"; then
        ctld_port=$p
        break
    fi
done
[ -n "$ctld_port" ] || skip "found no two free TCP ports in 20000-50000"
slurmd_port=$((ctld_port + 1))

# --- munge ------------------------------------------------------------------------------------
munge_socket=$work/munge/munge.socket
dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 status=none
chmod 0400 "$work/munge/munge.key"
munged --foreground --force --socket="$munge_socket" --key-file="$work/munge/munge.key" \
    --pid-file="$work/run/munged.pid" --log-file="$work/log/munged.log" \
    --seed-file="$work/munge/munged.seed" >"$work/log/munged.stdout.log" 2>&1 &
pids+=("$!:munged")
for ((i = 0; i < 100; i++)); do
    [ -S "$munge_socket" ] && break
    kill -0 "${pids[0]%%:*}" 2>/dev/null || break
    sleep 0.1
done
munge --socket="$munge_socket" -n 2>"$work/log/munge-check.log" | unmunge --socket="$munge_socket" >/dev/null 2>>"$work/log/munge-check.log" ||
    skip "munged did not start or does not answer on $munge_socket"
say "munged up"

# --- slurm.conf -------------------------------------------------------------------------------
export SLURM_CONF=$work/slurm.conf
cat >"$SLURM_CONF" <<EOF
# One-node cluster for toonray's integration test; everything lives in $work.
ClusterName=toonraytest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$munge_socket
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/run/slurmctld.pid
SlurmdPidFile=$work/run/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/builtin
MpiDefault=none
MailProg=/bin/true
ReturnToService=2
SlurmdParameters=config_overrides
MinJobAge=600
KillWait=5
InactiveLimit=0
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=512 State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF

# --- slurmctld --------------------------------------------------------------------------------
slurmctld -D -c -f "$SLURM_CONF" >"$work/log/slurmctld.stdout.log" 2>&1 &
ctld_pid=$!
pids+=("$ctld_pid:slurmctld")
up=0
for ((i = 0; i < 300; i++)); do
    kill -0 "$ctld_pid" 2>/dev/null || break
    if scontrol ping 2>/dev/null | grep -q "is UP"; then
        up=1
        break
    fi
    sleep 0.1
done
((up)) || skip "slurmctld did not start (port $ctld_port)"
say "slurmctld up on port $ctld_port"

# --- slurmd -----------------------------------------------------------------------------------
slurmd -D -f "$SLURM_CONF" -N "$host" >"$work/log/slurmd.stdout.log" 2>&1 &
slurmd_pid=$!
pids+=("$slurmd_pid:slurmd")
state=""
for ((i = 0; i < 300; i++)); do
    kill -0 "$slurmd_pid" 2>/dev/null || break
    state=$(sinfo -h -n "$host" -o %T 2>/dev/null || true)
    [ "$state" = idle ] && break
    sleep 0.1
done
kill -0 "$slurmd_pid" 2>/dev/null || skip "slurmd exited while starting"
[ "$state" = idle ] || skip "node $host did not become idle within 30 s (state '$state')"
say "slurmd up on port $slurmd_port; node $host idle with $cpus CPUs"

# --- the frames -------------------------------------------------------------------------------
# Ten copies of the teapot, each with a camera block that moves the eye along x; frames 1-9 go
# to in/, frame 10 waits in all/ for step 3.
mkdir -p "$work/all" "$work/in"
teapot=$repo/tests/data/teapot.obj
for f in $(seq 1 10); do
    x=$(awk -v f="$f" 'BEGIN { printf "%.3f", -3 + 0.6 * (f - 1) }')
    {
        cat "$teapot"
        printf '# camera for frame %d\nv %s 2 8\nv 0 0.8 0\nvn 0 1 0\nc -2 -1 -1\n' "$f" "$x"
    } >"$work/all/$(printf 'keys_%06d.obj' "$f")"
done
cp "$work"/all/keys_00000[1-9].obj "$work/in/"
"$toonray" batch keys 1 10 --input "$work/all" --output "$work/ref" --jobs 1 --quiet --size 160x90 ||
    fail "the local reference render failed"
say "reference frames rendered locally"

# --- helpers for the jobs ---------------------------------------------------------------------
submit() { # sbatch arguments...; prints the job id
    local out
    out=$(cd "$work/job" && sbatch --parsable "$@" 2>&1) || fail "sbatch $* failed: $out"
    out=${out%%;*}
    [[ $out =~ ^[0-9]+$ ]] || fail "sbatch printed no job id: $out"
    echo "$out"
}

# Waits until every task of array job $1 (with $2 tasks) has ended; then prints one line
# "TASK STATE EXITCODE" per task, sorted by task.
wait_array() {
    local job=$1 ntasks=$2 records lines ended
    while :; do
        records=$(scontrol -o show job "$job" 2>&1) || fail "scontrol show job $job: $records"
        lines=$(sed -nE 's/.* ArrayTaskId=([0-9]+) .* JobState=([A-Z_]+) .* ExitCode=([0-9]+:[0-9]+).*/\1 \2 \3/p' <<<"$records" | sort -n)
        ended=$(grep -cE ' (COMPLETED|FAILED|CANCELLED|TIMEOUT|NODE_FAIL|OUT_OF_MEMORY|BOOT_FAIL|DEADLINE|PREEMPTED) ' <<<"$lines" || true)
        if [ "$ended" -eq "$ntasks" ] && [ "$(wc -l <<<"$records")" -eq "$ntasks" ]; then
            echo "$lines"
            return
        fi
        ((SECONDS < deadline)) || fail "job $job not finished after ${timeout_total} s: $(sed -nE "s/.*(ArrayTaskId=[^ ]+).*(JobState=[^ ]+).*/\\1 \\2/p" <<<"$records" | tr "\\n" ";")"
        if grep -q "Reason=ReqNodeNotAvail\|Reason=PartitionConfig\|Reason=BadConstraints" <<<"$records"; then
            fail "job $job cannot run: $(grep -o 'Reason=[^ ]*' <<<"$records" | sort -u | tr '\n' ' ')"
        fi
        sleep 0.5
    done
}

expect_tasks() { # job "TASK STATE EXIT" lines...
    local job=$1 actual
    shift
    actual=$(wait_array "$job" $#)
    local expected
    expected=$(printf '%s\n' "$@")
    [ "$actual" = "$expected" ] || fail "job $job: tasks ended as
$actual
expected
$expected"
    say "job $job: $(tr '\n' ',' <<<"$actual" | sed 's/,$//')"
}

# out/ must hold exactly frames 1..$1, each equal to the reference, and nothing else (no
# temporary .keys_*.tmp.* files either).
check_frames() {
    local last=$1 expected actual f
    expected=$(for f in $(seq 1 "$last"); do printf 'keys_%06d.png\n' "$f"; done)
    actual=$(find "$work/out" -mindepth 1 -printf "%f\n" 2>/dev/null | LC_ALL=C sort)
    [ "$actual" = "$expected" ] || fail "out/ should hold exactly frames 1-$last, but holds: $(tr '\n' ' ' <<<"$actual")"
    for f in $expected; do
        cmp -s "$work/ref/$f" "$work/out/$f" || fail "out/$f differs from the local render ref/$f"
    done
}

inodes() { (cd "$work/out" && stat -c '%n %i %Y' keys_00000[1-9].png); }

job_log() { # array job, task
    local log="$work/job/toonray-render-$1_$2.log"
    [ -f "$log" ] || fail "no log $log (the #SBATCH --output pattern %x-%A_%a.log)"
    echo "$log"
}

# --- 1: a 3-task array renders frames 1-9 -----------------------------------------------------
t0=$SECONDS
job=$(TOONRAY=$toonray submit --array=1-3 "$sbatch_script" keys 1 9 ../in ../out --size 160x90)
submitted+=("$job")
say "step 1: submitted array job $job (3 tasks, frames 1-9)"
expect_tasks "$job" "1 COMPLETED 0:0" "2 COMPLETED 0:0" "3 COMPLETED 0:0"
for k in 1 2 3; do
    log=$(job_log "$job" "$k")
    grep -q "shard $k/3 " "$log" || fail "the log of task $k does not name shard $k/3: $(cat "$log")"
    grep -q "3 rendered, 0 skipped, 0 failed of 3 frames" "$log" || fail "task $k did not render its 3 frames: $(cat "$log")"
done
check_frames 9
say "step 1 passed in $((SECONDS - t0)) s: 9 frames, each once, identical to the local render"

# --- 2: a missing frame fails its task; finished frames are not rendered again ----------------
t0=$SECONDS
before=$(inodes)
job=$(TOONRAY=$toonray submit --array=1-2 "$sbatch_script" keys 1 10 ../in ../out --size 160x90)
submitted+=("$job")
say "step 2: submitted array job $job (2 tasks, frames 1-10, frame 10 missing)"
# Frame 10 is at position 9 of the range: shard 9 mod 2 + 1 = 2.
expect_tasks "$job" "1 COMPLETED 0:0" "2 FAILED 1:0"
log=$(job_log "$job" 2)
grep -q "frame 10 failed" "$log" || fail "the log of task 2 does not report frame 10: $(cat "$log")"
grep -q "failed frames: 10" "$log" || fail "the log of task 2 has no failure summary: $(cat "$log")"
check_frames 9
[ "$(inodes)" = "$before" ] || fail "--resume should have kept frames 1-9 as they were"
say "step 2 passed in $((SECONDS - t0)) s: task 2 failed with exit code 1, frames 1-9 kept"

# --- 3: with frame 10 in place, the same submission completes (toonray found on PATH) --------
t0=$SECONDS
cp "$work/all/keys_000010.obj" "$work/in/"
job=$(PATH="$(dirname "$toonray"):$PATH" submit --array=1-2 "$sbatch_script" keys 1 10 ../in ../out --size 160x90)
submitted+=("$job")
say "step 3: submitted array job $job (2 tasks, frames 1-10)"
expect_tasks "$job" "1 COMPLETED 0:0" "2 COMPLETED 0:0"
grep -q "0 rendered, 5 skipped, 0 failed of 5 frames" "$(job_log "$job" 1)" || fail "task 1 should have skipped its 5 frames"
grep -q "1 rendered, 4 skipped, 0 failed of 5 frames" "$(job_log "$job" 2)" || fail "task 2 should have rendered frame 10 only"
check_frames 10
[ "$(inodes)" = "$before" ] || fail "--resume should have kept frames 1-9 as they were"
say "step 3 passed in $((SECONDS - t0)) s: frame 10 added, frames 1-9 kept"

say "PASS in $SECONDS s"
