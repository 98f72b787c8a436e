//! CIEDE2000 against Sharma, Wu and Dalal's published test pairs.
use sunbeam_optics::colour::ciede2000;

#[test]
fn sharma_pairs() {
    let text = include_str!("data/ciede2000_sharma.txt");
    let mut n = 0;
    for line in text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
    {
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|s| s.parse().unwrap())
            .collect();
        let (a, b) = ([v[0], v[1], v[2]], [v[3], v[4], v[5]]);
        let d = ciede2000(a, b);
        assert!((d - v[6]).abs() < 1e-4, "pair {n}: {d} vs {}", v[6]);
        assert!((ciede2000(b, a) - v[6]).abs() < 1e-4, "pair {n} reversed");
        n += 1;
    }
    assert_eq!(n, 34);
    assert_eq!(ciede2000([50.0, 10.0, -3.0], [50.0, 10.0, -3.0]), 0.0);
}
