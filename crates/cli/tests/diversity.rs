//! Quality-diversity runs through the real binary, on the thesis's roobot
//! (scenes/hop_map.toml): archive.csv with pyribs's columns, every elite a
//! scene that `evaluate` reproduces bit for bit (fitness and measures), the
//! same archive on 1 and 2 threads and after a resume, log.csv's archive
//! columns, and bad requests refused with exit 2.

mod common;
use common::*;

const HOP_MAP: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/hop_map.toml");

fn evolve(optimiser: &str, generations: &str, threads: &str, name: &str) -> std::path::PathBuf {
    let dir = scratch(name);
    let o = animats(&[
        "evolve",
        HOP_MAP,
        "--optimiser",
        optimiser,
        "--generations",
        generations,
        "--population",
        "12",
        "--threads",
        threads,
        "--out",
        dir.to_str().unwrap(),
    ]);
    let (_, err) = text(&o);
    assert!(o.status.success(), "{optimiser}: {err}");
    dir
}

fn read(dir: &std::path::Path, file: &str) -> String {
    std::fs::read_to_string(dir.join(file)).unwrap()
}

#[test]
fn elites_reproduce_and_archives_do_not_depend_on_threads_or_resume() {
    for optimiser in ["map-elites", "cma-me"] {
        let dir = evolve(optimiser, "4", "2", &format!("qd-{optimiser}-2"));
        let csv = read(&dir, "archive.csv");
        let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
        assert_eq!(
            header[..8],
            [
                "index",
                "objective",
                "measures_0",
                "measures_1",
                "threshold",
                "time",
                "distance",
                "ended"
            ]
        );
        let rows: Vec<Vec<&str>> = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').collect())
            .collect();
        assert!(!rows.is_empty(), "{optimiser}: an empty archive");
        // Every elite: a scene file that evaluates to its row, bit for bit.
        for row in rows.iter().take(3) {
            let scene = dir.join("elites").join(format!("{}.toml", row[0]));
            let o = animats(&["evaluate", scene.to_str().unwrap(), "--json"]);
            let (json, err) = text(&o);
            assert!(o.status.success(), "{err}");
            let v: serde_json::Value = serde_json::from_str(&json).unwrap();
            let objective: f64 = row[1].parse().unwrap();
            assert_eq!(v["fitness"].as_f64(), Some(objective), "{json}");
            for k in 0..2 {
                let m: f64 = row[2 + k].parse().unwrap();
                assert_eq!(v["measures"][k].as_f64(), Some(m), "{json}");
            }
            // Only whole 20 s runs enter this map (min_time = 20).
            assert_eq!(row[5], "20.0");
        }
        assert_eq!(
            std::fs::read_dir(dir.join("elites")).unwrap().count(),
            rows.len()
        );
        assert!(dir.join("archive.png").exists());
        let log = read(&dir, "log.csv");
        assert!(log
            .lines()
            .next()
            .unwrap()
            .ends_with(",elites,coverage,qd_score,obj_max"));
        let last: Vec<&str> = log.lines().last().unwrap().split(',').collect();
        assert_eq!(last[last.len() - 4], rows.len().to_string());
        // `view DIR --elite CELL` serves that elite (Ctrl-C stops it).
        if optimiser == "map-elites" {
            watch_elite(&dir, rows[0][0]);
        }
        // One thread: the same bits.
        let one = evolve(optimiser, "4", "1", &format!("qd-{optimiser}-1"));
        assert_eq!(
            read(&one, "archive.csv"),
            csv,
            "{optimiser}: 1 thread against 2"
        );
        assert_eq!(read(&one, "log.csv"), log);
        // Two generations, then resumed to four: the same bits.
        let part = evolve(optimiser, "2", "2", &format!("qd-{optimiser}-part"));
        let o = animats(&[
            "evolve",
            "--resume",
            part.to_str().unwrap(),
            "--generations",
            "4",
        ]);
        assert!(o.status.success(), "{}", text(&o).1);
        assert_eq!(read(&part, "archive.csv"), csv, "{optimiser}: resumed");
        assert_eq!(read(&part, "log.csv"), log);
    }
}

/// Starts `animats view DIR --elite CELL` on a free port, waits for its
/// address, and stops it with Ctrl-C: exit 0 with a summary.
fn watch_elite(dir: &std::path::Path, cell: &str) {
    use std::io::{BufRead, BufReader, Read};
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_animats"))
        .args([
            "view",
            dir.to_str().unwrap(),
            "--elite",
            cell,
            "--port",
            "0",
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    out.read_line(&mut line).unwrap();
    assert!(line.contains("http://127.0.0.1:"), "{line}");
    std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    let status = child.wait().unwrap();
    let mut rest = String::new();
    out.read_to_string(&mut rest).unwrap();
    assert_eq!(status.code(), Some(0), "{rest}");
}

#[test]
fn bad_requests_are_refused() {
    let dir = scratch("qd-bad");
    let d = dir.to_str().unwrap();
    let walker = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/walker.toml");
    for (args, says) in [
        (
            vec!["evolve", walker, "--optimiser", "map-elites", "--out", d],
            "[archive]",
        ),
        (
            vec![
                "evolve",
                HOP_MAP,
                "--optimiser",
                "cma-me",
                "--lanes",
                "3",
                "--out",
                d,
            ],
            "lanes",
        ),
    ] {
        let o = animats(&args);
        let (_, err) = text(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
    }
    // An elite that is not in the map; --elite on a file.
    let run = evolve("map-elites", "1", "2", "qd-bad-view");
    for (args, says) in [
        (
            vec![
                "view",
                run.to_str().unwrap(),
                "--elite",
                "987654",
                "--port",
                "0",
            ],
            "no elite in cell 987654",
        ),
        (
            vec!["view", HOP_MAP, "--elite", "3", "--port", "0"],
            "is a file",
        ),
    ] {
        let o = animats(&args);
        let (_, err) = text(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
    }
    // A malformed [archive]: evaluate and evolve both refuse it, naming
    // the file and the field.
    let good = std::fs::read_to_string(HOP_MAP).unwrap();
    for (from, to, says) in [
        (
            "ranges = [[0.3, 1.0], [-1.0, 3.0]]",
            "ranges = [[0.3, 1.0], [3.0, 3.0]]",
            "archive.ranges[1]",
        ),
        ("bins = [20, 20]", "bins = [20]", "archive.bins"),
        (
            "bins = [20, 20]",
            "bins = [20, 20]\ntournament = 0",
            "archive.tournament",
        ),
        (
            "bins = [20, 20]",
            "bins = [20000, 20000]",
            "at most 10000000",
        ),
        (
            r#"{ kind = "speed" }"#,
            r#"{ kind = "grace" }"#,
            "archive.measures[1]",
        ),
    ] {
        assert!(good.contains(from), "{from}");
        let bad = write(&dir, "bad.toml", &good.replace(from, to));
        for args in [
            vec!["evaluate", bad.as_str()],
            vec![
                "evolve",
                bad.as_str(),
                "--optimiser",
                "map-elites",
                "--out",
                d,
            ],
        ] {
            let o = animats(&args);
            let (_, err) = text(&o);
            assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
            assert!(
                err.contains("bad.toml") && err.contains(says),
                "{args:?}: {err}"
            );
        }
    }
}
