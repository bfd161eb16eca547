//! Per-client rate limiting of edits: a token bucket for each client address.

use std::collections::HashMap;
use std::net::IpAddr;
use std::sync::{Mutex, PoisonError};
use std::time::{Duration, Instant};

/// Buckets idle this long are full again and are dropped when the table is pruned.
const IDLE: Duration = Duration::from_secs(600);
/// The table is pruned of idle buckets when it holds more than this many.
const PRUNE_ABOVE: usize = 4096;

/// Token buckets keyed by client address (`None`: the client's address is unknown, as in
/// in-process tests; such clients share one bucket).
#[derive(Debug)]
pub(crate) struct RateLimiter {
    rate: f64,
    burst: f64,
    buckets: Mutex<HashMap<Option<IpAddr>, Bucket>>,
}

#[derive(Debug, Clone, Copy)]
struct Bucket {
    tokens: f64,
    at: Instant,
}

impl RateLimiter {
    /// `burst` tokens per client, refilled at `rate` tokens per second.
    pub fn new(rate: f64, burst: u32) -> RateLimiter {
        RateLimiter {
            rate,
            burst: f64::from(burst),
            buckets: Mutex::new(HashMap::new()),
        }
    }

    /// Takes one token for `client` at time `now`: `Ok` when it had one, else `Err` with how long
    /// until it has.
    pub fn take(&self, client: Option<IpAddr>, now: Instant) -> Result<(), Duration> {
        let mut buckets = self.buckets.lock().unwrap_or_else(PoisonError::into_inner);
        if buckets.len() > PRUNE_ABOVE {
            buckets.retain(|_, b| now.saturating_duration_since(b.at) < IDLE);
        }
        let b = buckets.entry(client).or_insert(Bucket {
            tokens: self.burst,
            at: now,
        });
        let elapsed = now.saturating_duration_since(b.at).as_secs_f64();
        b.tokens = (b.tokens + elapsed * self.rate).min(self.burst);
        b.at = now;
        if b.tokens >= 1.0 {
            b.tokens -= 1.0;
            Ok(())
        } else {
            Err(Duration::from_secs_f64((1.0 - b.tokens) / self.rate))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_burst_then_the_rate() {
        let r = RateLimiter::new(2.0, 3);
        let t0 = Instant::now();
        let a = Some(IpAddr::from([10, 0, 0, 1]));
        let b = Some(IpAddr::from([10, 0, 0, 2]));
        for _ in 0..3 {
            assert!(r.take(a, t0).is_ok());
        }
        let wait = r.take(a, t0).unwrap_err();
        assert!(
            (wait.as_secs_f64() - 0.5).abs() < 1e-9,
            "one token takes 1/rate: {wait:?}"
        );
        assert!(r.take(b, t0).is_ok(), "other clients have their own bucket");
        assert!(r.take(a, t0 + Duration::from_millis(499)).is_err());
        assert!(r.take(a, t0 + Duration::from_millis(1000)).is_ok());
        // A long pause refills up to the burst, not beyond.
        let later = t0 + Duration::from_secs(3600);
        for _ in 0..3 {
            assert!(r.take(a, later).is_ok());
        }
        assert!(r.take(a, later).is_err());
    }

    #[test]
    fn the_table_is_pruned_of_idle_clients() {
        let r = RateLimiter::new(1.0, 1);
        let t0 = Instant::now();
        for i in 0..=PRUNE_ABOVE as u32 {
            let _ = r.take(Some(IpAddr::from(i.to_be_bytes())), t0);
        }
        let _ = r.take(None, t0 + IDLE + Duration::from_secs(1));
        assert_eq!(r.buckets.lock().unwrap().len(), 1);
    }
}
