"""ambseal.control"""
