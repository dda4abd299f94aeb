"""ambseal.identify"""
