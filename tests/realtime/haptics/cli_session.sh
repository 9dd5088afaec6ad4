#!/usr/bin/env bash
# The live rig from the command line, as an experimenter runs it, over loopback:
#  1. kerf-rig device-sim + kerf-rig haptic --record: the session's model forces equal an offline
#     `kerf run --trajectory SESSION` of the same scene (to 1e-9 N, the model is deterministic);
#  2. device-sim killed with SIGKILL mid-session: every tick whose link is as old as the 10 ms
#     watchdog commands exactly zero, and there are such ticks;
#  3. SIGTERM to kerf-rig haptic is an emergency stop: it exits 0 and says so;
#  4. --device-model: an unknown name, or --max-force above the named device's maximum, is refused;
#  5. kerf-rig replay SESSION: the recorded hand motion through the servo loop again, with the
#     session's model and rate; the replay holds the recording's last sample once it is played, so
#     its last position is the session's last position exactly.
# Ports are picked by the kernel (--port 0) and read from device-sim's output, so parallel runs
# do not collide. Usage: cli_session.sh KERF_RIG KERF SCENE WORKDIR
set -euo pipefail
KERF_RIG=$1 KERF=$2 SCENE=$3 WORK=$4
rm -rf "$WORK" && mkdir -p "$WORK" && cd "$WORK"

start_sim() { # $1 = log file; prints the port
  "$KERF_RIG" device-sim "$SCENE" --port 0 --hand-stiffness 3000 --hold 0.3 --tail 0.3 "${@:2}" > "$1" 2>&1 &
  SIM=$!
  for _ in $(seq 100); do grep -q "udp://" "$1" && break; sleep 0.05; done
  PORT=$(sed -n 's|.*udp://127.0.0.1:\([0-9]*\),.*|\1|p' "$1" | head -1)
  [ -n "$PORT" ] || { cat "$1"; echo "device-sim did not start"; exit 1; }
}

wait_ticks() { # $1 = session file, $2 = rows: wait (at most 120 s) until the rig has recorded them
  for _ in $(seq 1200); do [ -f "$1" ] && [ "$(wc -l < "$1")" -gt "$2" ] && return 0; sleep 0.1; done
  echo "the rig never recorded $2 rows in $1"; exit 1
}

# 1. session vs offline run
start_sim sim1.log --record received.csv
"$KERF_RIG" haptic "$SCENE" --model fracture --device "udp://127.0.0.1:$PORT" --duration 2.3 --record session.csv \
  --no-realtime > haptic1.log 2>&1
wait $SIM
"$KERF" run "$SCENE" --model fracture --trajectory session.csv -o offline > run.log
# session rows: 3 header lines, model force in columns 15-17; profile: 1 header line, force in 6-8
paste -d, <(tail -n +4 session.csv | cut -d, -f15-17,21) <(tail -n +2 offline/profile.csv | cut -d, -f6-9) |
  awk -F, '{ d = 0; for (i = 1; i <= 3; ++i) { e = $i - $(i + 4); if (e < 0) e = -e; if (e > d) d = e }
             if (d > 1e-9 || $4 != $8) { print "row " NR ": session " $0; bad = 1 }
             if ($4 == "cutting") cut = 1; n++ }
           END { if (n < 1000) { print "only " n " ticks"; bad = 1 } if (!cut) { print "no cutting"; bad = 1 }
                 exit bad }'
[ "$(tail -n +2 received.csv | wc -l)" -gt 1000 ] || { echo "device-sim received too few commands"; exit 1; }
echo "1. session matches the offline run ($(tail -n +4 session.csv | wc -l) ticks)"

# 1b. the same session through the finite-element reference: its tool path is the recorded one
# (one row per session tick in the replayed trajectory), its load path through the hand's turns
# (every vertex of the recorded motion beyond 10 µm) besides 3 evenly spaced output samples, over
# the first 0.6 s — the approach and the first millimetres of the cut — with adaptive sampling off
# and the body deforming only (fracture off, which a cutting scene has on by default and which is
# not what this step checks; pressed uncut to the cut's full depth the razor would stop the path).
"$KERF" reference "$SCENE" --trajectory session.csv --samples 3 --until 0.6 --vertex-tolerance 0.01 --adaptive 0 --fracture off \
  --no-fields -o replayed > reference.log 2>&1 || { cat reference.log; exit 1; }
[ "$(tail -n +2 replayed/session_blade.csv | wc -l)" -eq "$(tail -n +4 session.csv | wc -l)" ] ||
  { echo "the replayed trajectory does not have one row per session tick"; exit 1; }
planned=$(sed -n 's/.*"loads_planned": *\([0-9]*\).*/\1/p' replayed/manifest.json | head -1)
rows=$(tail -n +2 replayed/profile.csv | wc -l)
[ -n "$planned" ] && [ "$rows" -eq "$planned" ] && [ "$rows" -ge 3 ] ||
  { echo "expected every planned load (the 3 samples and the hand's turns: ${planned:-?}) in the profile, got $rows rows"; exit 1; }
echo "1b. kerf reference --trajectory replays the session"

# 2. SIGKILL the device mid-session
start_sim sim2.log
"$KERF_RIG" haptic "$SCENE" --model fracture --device "udp://127.0.0.1:$PORT" --duration 6 --record killed.csv \
  --no-realtime > haptic2.log 2>&1 &
RIG=$!
wait_ticks killed.csv 500 # the rig is live (meshing first takes a while on a loaded machine)
kill -KILL $SIM
wait $SIM || true
wait $RIG
# column 25 = link_age_s, 18-20 = commanded force
tail -n +4 killed.csv | awk -F, '$25 >= 0.01 - 1e-9 { silent++; if ($18 != 0 || $19 != 0 || $20 != 0) { print "nonzero force at link age " $25 ": " $0; bad = 1 } }
  END { if (silent < 100) { print "only " silent " silent ticks"; bad = 1 } exit bad }'
echo "2. killed device: zero force once the link is older than the watchdog time"

# 3. SIGTERM to the rig is an emergency stop
start_sim sim3.log
"$KERF_RIG" haptic "$SCENE" --model fracture --device "udp://127.0.0.1:$PORT" --no-realtime --record estop.csv \
  > haptic3.log 2>&1 &
RIG=$!
wait_ticks estop.csv 300
kill -TERM $RIG
wait $RIG
grep -q "emergency stop" haptic3.log || { cat haptic3.log; echo "no emergency stop reported"; exit 1; }
kill -INT $SIM 2>/dev/null || true
wait $SIM || true
echo "3. SIGTERM: emergency stop, exit 0"

# 4. a named device gives its limits; an unknown one, or a clamp above the device's, is an error
"$KERF_RIG" haptic "$SCENE" --model fracture --device udp://127.0.0.1:9 --device-model phantom > model1.log 2>&1 &&
  { echo "an unknown --device-model was accepted"; exit 1; }
grep -q "unknown device model 'phantom'.*touch" model1.log || { cat model1.log; echo "no error naming the model"; exit 1; }
"$KERF_RIG" haptic "$SCENE" --model fracture --device udp://127.0.0.1:9 --device-model touch --max-force 5 > model2.log 2>&1 &&
  { echo "--max-force above the Touch's 3.3 N was accepted"; exit 1; }
grep -q "exceeds the 3D Systems Touch's maximum force 3.3" model2.log || { cat model2.log; echo "no error naming the limit"; exit 1; }
echo "4. --device-model: unknown names and clamps above the device's maximum are refused"

# 5. the recorded session through the servo loop again
"$KERF_RIG" replay session.csv --scene "$SCENE" --no-realtime --record replay.csv > replay.log 2>&1 ||
  { cat replay.log; echo "replay failed"; exit 1; }
grep -q "session ended" replay.log || { cat replay.log; echo "the replay did not end by itself"; exit 1; }
[ "$(sed -n 2p replay.csv)" = "$(sed -n 2p session.csv)" ] ||
  { sed -n 2p replay.csv session.csv; echo "the replay's header (rate, model, scene, tools) differs"; exit 1; }
[ "$(tail -n 1 replay.csv | cut -d, -f4-6)" = "$(tail -n 1 session.csv | cut -d, -f4-6)" ] ||
  { tail -n 1 replay.csv session.csv; echo "the replay does not end at the session's last position"; exit 1; }
[ "$(tail -n +4 replay.csv | wc -l)" -ge "$(tail -n +4 session.csv | wc -l)" ] ||
  { echo "the replay is shorter than the session"; exit 1; }
awk -F, 'NR > 3 && $21 == "cutting" { n++ } END { exit !n }' replay.csv || { echo "the replay never cuts"; exit 1; }
echo "5. kerf-rig replay: the session's motion again, ending at its last position"
