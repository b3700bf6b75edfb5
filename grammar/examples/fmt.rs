fn main() {
    let path = std::env::args().nth(1).expect("path");
    let text = std::fs::read_to_string(path).expect("read");
    match ratecal_grammar::parse(&text) {
        Ok(f) => print!("{}", ratecal_grammar::format(&f)),
        Err(e) => eprintln!(
            "{}",
            e.with_source(&ratecal_grammar::source("x", &text)).render()
        ),
    }
}
