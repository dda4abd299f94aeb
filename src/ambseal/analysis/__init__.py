"""ambseal.analysis"""
