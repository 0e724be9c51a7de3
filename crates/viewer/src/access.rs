//! Who may watch and steer: on a loopback address anyone on this machine;
//! on any other address only a browser that shows the random token printed
//! in the URL (as Jupyter does), since the page can pause, reset and move
//! things. The page (`/`) and the WebSocket (`/ws`) check it; the static
//! scripts hold nothing about the run and are served to anyone.

use std::collections::hash_map::RandomState;
use std::hash::{BuildHasher, Hasher};
use std::net::{IpAddr, ToSocketAddrs};

/// A fresh random token: 128 bits as 32 hex digits. Each `RandomState` is
/// keyed from the operating system's random source.
pub fn new_token() -> String {
    (0..2)
        .map(|i| {
            let mut h = RandomState::new().build_hasher();
            h.write_u64(i);
            format!("{:016x}", h.finish())
        })
        .collect()
}

/// True when `host` names only this machine (127.0.0.0/8, ::1, localhost).
pub fn is_loopback(host: &str) -> bool {
    match host.parse::<IpAddr>() {
        Ok(ip) => ip.is_loopback(),
        Err(_) => (host, 0)
            .to_socket_addrs()
            .map(|mut addrs| addrs.all(|a| a.ip().is_loopback()))
            .unwrap_or(false),
    }
}

/// True when the query string `query` carries `token=<expected>`. The
/// comparison takes the same time wherever the strings differ.
pub fn allowed(expected: Option<&str>, query: Option<&str>) -> bool {
    let Some(expected) = expected else {
        return true;
    };
    let given = query
        .unwrap_or("")
        .split('&')
        .find_map(|kv| kv.strip_prefix("token="))
        .unwrap_or("");
    given.len() == expected.len()
        && given
            .bytes()
            .zip(expected.bytes())
            .fold(0u8, |d, (a, b)| d | (a ^ b))
            == 0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_are_long_and_differ() {
        let (a, b) = (new_token(), new_token());
        assert_eq!(a.len(), 32);
        assert_ne!(a, b);
    }

    #[test]
    fn only_the_exact_token_is_allowed() {
        let t = Some("0123abcd");
        assert!(allowed(t, Some("token=0123abcd")));
        assert!(allowed(t, Some("x=1&token=0123abcd")));
        assert!(!allowed(t, Some("token=0123abce")));
        assert!(!allowed(t, Some("token=0123abcd0")));
        assert!(!allowed(t, Some("token=")));
        assert!(!allowed(t, None));
        assert!(allowed(None, None));
    }

    #[test]
    fn loopback_names() {
        assert!(is_loopback("127.0.0.1"));
        assert!(is_loopback("127.4.5.6"));
        assert!(is_loopback("::1"));
        assert!(is_loopback("localhost"));
        assert!(!is_loopback("0.0.0.0"));
        assert!(!is_loopback("::"));
        assert!(!is_loopback("192.168.1.4"));
    }
}
