//! The host-link commands: every request of the frame format, and every malformed,
//! oversize, unknown or out-of-range one, which must get an `ERR` reply and leave the
//! loop exactly as it was.
use needle_haptics::command::{self, parse, Command, FrameError, FrameReader, FRAME_MAX};
use needle_haptics::control::{ChannelMap, LoopConfig, LoopCore, OverLimit, PoseFault};
use needle_haptics::{model_info, Pose};
use rand::{Rng, SeedableRng};

fn core() -> LoopCore<2> {
    let config = LoopConfig {
        channels: [
            ChannelMap { gains_per_n: [0.0, 10.0, 0.0], direction_inverted: false },
            ChannelMap { gains_per_n: [10.0, 0.0, 0.0], direction_inverted: true },
        ],
        force_limit_n: 1.5,
        force_limit_max_n: 4.0,
        over_limit: OverLimit::Saturate,
        ramp_step_n: 0.01,
    };
    let mut c = LoopCore::new(config).expect("valid");
    c.step(Ok(Pose::new(1.0, 2.0, 3.0, 0.0, 4.0)));
    c.step(Err(PoseFault::Stale));
    c
}

/// Feeds `bytes` through a frame reader and answers every complete line.
fn talk(core: &mut LoopCore<2>, bytes: &[u8]) -> Vec<String> {
    let mut reader = FrameReader::new();
    let mut replies = Vec::new();
    for b in bytes {
        if let Some(frame) = reader.push(*b) {
            replies.push(command::respond(frame, core, 7).to_string());
        }
    }
    replies
}

#[test]
fn every_command_and_its_reply() {
    let mut c = core();
    let r = talk(&mut c, b"PING\nSTATUS\nMODEL\nLIMIT\nMODE\n");
    assert_eq!(r[0], "OK PONG\n");
    assert_eq!(r[1], "OK STATUS tick=2 flags=0x0021 model=0x00 limit_mn=1500 mode=SAT dropped=7\n");
    let m = format!(
        "OK MODEL set={} fitted={} fe_sha256={} x_mm=12 z_mm=12 theta_deg=15 depth_mm=6\n",
        model_info::SET,
        u8::from(model_info::FITTED),
        &model_info::FE_SHA256[..16]
    );
    assert_eq!(r[2], m);
    assert_eq!(r[3], "OK LIMIT limit_mn=1500\n");
    assert_eq!(r[4], "OK MODE SAT\n");

    let r = talk(&mut c, b"LIMIT 2500\r\nMODE RAMP\nSTATUS\n");
    assert_eq!(
        r,
        ["OK LIMIT limit_mn=2500\n", "OK MODE RAMP\n", "OK STATUS tick=2 flags=0x0021 model=0x00 limit_mn=2500 mode=RAMP dropped=7\n"]
    );
    assert_eq!(c.config().force_limit_n, 2.5);
    assert_eq!(c.config().over_limit, OverLimit::RampToZero);
    let r = talk(&mut c, b"LIMIT 4000\nLIMIT 1\nMODE SAT\n");
    assert_eq!(r, ["OK LIMIT limit_mn=4000\n", "OK LIMIT limit_mn=1\n", "OK MODE SAT\n"]);
    assert_eq!(c.config().force_limit_n, 0.001);
}

#[test]
fn every_malformed_unknown_or_out_of_range_request_is_refused_and_changes_nothing() {
    let oversize = [b'P'; FRAME_MAX + 1];
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (b"".to_vec(), "ERR MALFORMED empty frame\n"),
        (b"\r".to_vec(), "ERR MALFORMED empty frame\n"),
        (b"PI\x00NG".to_vec(), "ERR MALFORMED byte outside printable ASCII\n"),
        (b"PING\t".to_vec(), "ERR MALFORMED byte outside printable ASCII\n"),
        (b"LIMIT \xff".to_vec(), "ERR MALFORMED byte outside printable ASCII\n"),
        (b"\x1b[A".to_vec(), "ERR MALFORMED byte outside printable ASCII\n"),
        (b" PING".to_vec(), "ERR MALFORMED words must be separated by one space\n"),
        (b"PING ".to_vec(), "ERR MALFORMED words must be separated by one space\n"),
        (b"LIMIT  100".to_vec(), "ERR MALFORMED words must be separated by one space\n"),
        (b" ".to_vec(), "ERR MALFORMED words must be separated by one space\n"),
        (b"LIMIT 100 200".to_vec(), "ERR MALFORMED too many words\n"),
        (b"LIMIT -100".to_vec(), "ERR MALFORMED a number is 1 to 9 decimal digits\n"),
        (b"LIMIT +100".to_vec(), "ERR MALFORMED a number is 1 to 9 decimal digits\n"),
        (b"LIMIT 1.5".to_vec(), "ERR MALFORMED a number is 1 to 9 decimal digits\n"),
        (b"LIMIT 0x10".to_vec(), "ERR MALFORMED a number is 1 to 9 decimal digits\n"),
        (b"LIMIT 1000000000".to_vec(), "ERR MALFORMED a number is 1 to 9 decimal digits\n"),
        (b"LIMIT abc".to_vec(), "ERR MALFORMED a number is 1 to 9 decimal digits\n"),
        (b"MODE FAST".to_vec(), "ERR MALFORMED MODE takes SAT or RAMP\n"),
        (b"MODE sat".to_vec(), "ERR MALFORMED MODE takes SAT or RAMP\n"),
        (b"PING 1".to_vec(), "ERR MALFORMED this command takes no argument\n"),
        (b"STATUS now".to_vec(), "ERR MALFORMED this command takes no argument\n"),
        (b"MODEL x".to_vec(), "ERR MALFORMED this command takes no argument\n"),
        (b"ping".to_vec(), "ERR UNKNOWN no such command\n"),
        (b"RESET".to_vec(), "ERR UNKNOWN no such command\n"),
        (b"FORCE 1".to_vec(), "ERR UNKNOWN no such command\n"),
        (b"LIMIT 0".to_vec(), "ERR RANGE limit_mn must be 1..=4000\n"),
        (b"LIMIT 4001".to_vec(), "ERR RANGE limit_mn must be 1..=4000\n"),
        (b"LIMIT 999999999".to_vec(), "ERR RANGE limit_mn must be 1..=4000\n"),
        (oversize.to_vec(), "ERR OVERSIZE frame longer than 32 bytes\n"),
        ([oversize.as_slice(), b"\r"].concat(), "ERR OVERSIZE frame longer than 32 bytes\n"),
        ([b"LIMIT 100 ".as_slice(), &[b'9'; 40]].concat(), "ERR OVERSIZE frame longer than 32 bytes\n"),
    ];
    for (frame, want) in &cases {
        let mut c = core();
        let before = c;
        let mut bytes = frame.clone();
        bytes.push(b'\n');
        let r = talk(&mut c, &bytes);
        assert_eq!(r.len(), 1, "{frame:?}: one reply per line");
        assert_eq!(r[0], *want, "{:?}", String::from_utf8_lossy(frame));
        assert_eq!(c, before, "{:?} changed the loop", String::from_utf8_lossy(frame));
        assert!(r[0].len() <= command::REPLY_MAX);
    }
    // The reader recovers after an oversize line: the next line is answered normally.
    let mut c = core();
    let mut bytes = vec![b'X'; 100];
    bytes.extend_from_slice(b"\nPING\n");
    assert_eq!(talk(&mut c, &bytes), ["ERR OVERSIZE frame longer than 32 bytes\n", "OK PONG\n"]);
}

#[test]
fn longest_frame_is_accepted() {
    // 32 bytes exactly: "LIMIT" + padding is not a valid number, so use the parser's limit
    // on an unknown but well-formed word.
    let frame = [b'A'; FRAME_MAX];
    assert_eq!(parse(&frame), Err(FrameError::Unknown));
    assert_eq!(parse(&[b'A'; FRAME_MAX + 1]), Err(FrameError::Oversize));
    assert_eq!(parse(b"LIMIT 2000"), Ok(Command::SetLimit { limit_mn: 2000 }));
}

#[test]
fn random_bytes_never_panic_and_only_ok_replies_change_the_loop() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(6);
    // Pieces of valid and invalid frames, so that both kinds occur.
    let pieces: [&[u8]; 16] = [
        b"PING", b"STATUS", b"MODEL", b"LIMIT", b"MODE", b"SAT", b"RAMP", b"2500", b"0", b"99999", b" ", b"\n", b"\n", b"\r", b"\x00",
        b"\xff",
    ];
    let mut c = core();
    let mut reader = FrameReader::new();
    let mut ok = 0;
    let mut err = 0;
    let bytes: Vec<u8> = (0..100_000).flat_map(|_| pieces[rng.gen_range(0..pieces.len())].iter().copied()).collect();
    for b in bytes {
        let before = c;
        if let Some(frame) = reader.push(b) {
            let reply = command::respond(frame, &mut c, 0);
            if reply.starts_with("ERR ") {
                err += 1;
                assert_eq!(c, before, "{reply}");
            } else {
                assert!(reply.starts_with("OK "), "{reply}");
                ok += 1;
            }
            assert!(reply.ends_with('\n'));
        }
    }
    assert!(ok > 0 && err > 0, "ok {ok}, err {err}");
}
