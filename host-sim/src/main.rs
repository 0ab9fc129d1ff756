//! `slf`: the command-line tool (grows with the host-simulator issue).

fn main() {
    println!(
        "slf {}: decoder core only; see README.md",
        env!("CARGO_PKG_VERSION")
    );
}
