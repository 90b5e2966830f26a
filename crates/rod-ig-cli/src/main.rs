fn main() {
    eprintln!("rod-ig: being written");
    std::process::exit(2);
}
