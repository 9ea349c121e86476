"""The book's spatial mathematics (Ch. 5 and the 002 text)."""
